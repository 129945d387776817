"""The removal operators end to end on the tiny room: remove, run again, save the HDRI, clear;
and a refused run that changes nothing."""
from __future__ import annotations

import gc
import importlib
import json
import threading
import time
import tracemalloc

import bpy
import numpy as np
import pytest

from tests.blender import tiny_scene


def test_remove_save_and_clear(room, tmp_path, extension):
    from diminished_reality.operators.support import world_layer

    world = bpy.context.scene.world
    links_before = {(link.from_node.name, link.to_node.name) for link in world.node_tree.links}

    assert bpy.ops.dimred.remove() == {'FINISHED'}
    difference_file = tmp_path / "dimred" / "Room_Probe_difference.exr"
    assert difference_file.is_file()
    assert world_layer.has_layer(world)
    assert json.loads(bpy.context.scene.dimred.last_report)["seconds"]["total"] > 0
    assert world_layer.layer_image(world).filepath == "//dimred/Room_Probe_difference.exr"
    difference = tiny_scene.read_exr(difference_file)
    np.testing.assert_array_equal(world_layer.image_rgb(world_layer.layer_image(world)), difference)

    assert bpy.ops.dimred.remove() == {'FINISHED'}
    assert sum(n.type == 'TEX_ENVIRONMENT' for n in world.node_tree.nodes) == 2

    edited_file = tmp_path / "edited.exr"
    assert bpy.ops.dimred.save_hdri(filepath=str(edited_file)) == {'FINISHED'}
    np.testing.assert_allclose(
        tiny_scene.read_exr(edited_file), tiny_scene.read_exr(room) + difference, rtol=1e-6, atol=1e-6
    )

    image_name = world_layer.layer_image(world).name
    assert bpy.ops.dimred.clear() == {'FINISHED'}
    assert {(link.from_node.name, link.to_node.name) for link in world.node_tree.links} == links_before
    assert image_name not in bpy.data.images


def test_refused_removal_changes_nothing(room, tmp_path):
    bpy.data.objects["Box"].hide_render = True

    with pytest.raises(RuntimeError, match="hidden for render"):
        bpy.ops.dimred.remove()

    assert not (tmp_path / "dimred").exists()
    assert bpy.context.scene.dimred.last_report == ""
    assert len(bpy.context.scene.world.node_tree.nodes) == 3


def test_a_panorama_too_big_for_the_free_memory_is_refused_before_any_work(room, tmp_path, extension, monkeypatch):
    memory = importlib.import_module(f"{extension.__name__}.addon.memory")
    monkeypatch.setattr(memory, "available_bytes", lambda: 50_000_000)

    with pytest.raises(RuntimeError, match=r"needs about .* GB of memory .* but only 0.1 GB is available"):
        bpy.ops.dimred.remove()

    assert not (tmp_path / "dimred").exists()
    assert bpy.context.scene.dimred.last_report == ""
    assert len(bpy.context.scene.world.node_tree.nodes) == 3


# -- the removal as the UI runs it: a worker thread polled by the modal operator's timer ---------

def _session(extension):
    return importlib.import_module(f"{extension.__name__}.operators.support.session")


def _links(world) -> set:
    return {(link.from_node.name, link.from_socket.identifier, link.to_node.name, link.to_socket.identifier)
            for link in world.node_tree.links}


def test_threaded_removal_previews_then_applies(room, tmp_path, extension, drive):
    from diminished_reality.operators.support import world_layer

    S = _session(extension)
    world = bpy.context.scene.world
    session = S.RemovalSession.begin(bpy.context)
    session.start()
    assert S.active() is session
    shown = []
    state = drive(session, on_tick=lambda s: shown.append(getattr(world_layer.preview_image(world), "name", None)))
    assert state == 'FINISHED', session.message
    # The coarse fill showed in the world before the result replaced it.
    assert S.PREVIEW_IMAGE in shown
    assert world_layer.preview_image(world) is None
    assert S.PREVIEW_IMAGE not in bpy.data.images and S.PREVIEW_MASK_IMAGE not in bpy.data.images
    assert S.active() is None
    difference = tiny_scene.read_exr(tmp_path / "dimred" / "Room_Probe_difference.exr")
    np.testing.assert_array_equal(world_layer.image_rgb(world_layer.layer_image(world)), difference)
    assert max(session.tick_seconds) < 0.1
    assert not [t for t in threading.enumerate() if t.name == "dimred-worker"]


def test_the_first_preview_shows_before_the_panorama_is_read(room, tmp_path, extension, monkeypatch):
    from addon.run import job, small_copy
    from diminished_reality.operators.support import warmup, world_layer

    S = _session(extension)
    cache = str(tmp_path / "cache")
    marked = warmup.running(str(room))  # marked by the fixture, making its copy elsewhere
    assert marked is None or marked.join(10.0)
    monkeypatch.setattr(warmup, "folder", lambda: cache)
    settings = bpy.context.scene.dimred
    settings.target = None
    settings.target = bpy.data.objects["Box"]  # marking makes the panorama's small copy
    making = warmup.running(str(room))  # None when the copy was made before this line
    assert making is None or making.join(10.0)
    assert small_copy.cached(str(room), cache) is not None
    reading, real = threading.Event(), job.read_exr
    monkeypatch.setattr(job, "read_exr", lambda path: (reading.wait(10.0), real(path))[1])

    session = S.RemovalSession.begin(bpy.context)
    session.start()
    world = bpy.context.scene.world
    deadline = time.perf_counter() + 10.0
    while world_layer.preview_image(world) is None and time.perf_counter() < deadline:
        session.tick(bpy.context)
        time.sleep(0.005)
    # Shown while the panorama's read is held up.
    assert world_layer.preview_image(world) is not None and not reading.is_set()
    reading.set()
    while session.tick(bpy.context) == 'RUNNING':
        time.sleep(0.01)
    assert session.ok, session.message


def test_opening_a_file_with_a_marked_object_prepares_its_panorama(room, tmp_path, extension, monkeypatch):
    from addon.run import small_copy
    from diminished_reality.operators.support import warmup

    marked = warmup.running(str(room))
    assert marked is None or marked.join(10.0)
    cache = str(tmp_path / "cache")
    monkeypatch.setattr(warmup, "folder", lambda: cache)
    bpy.ops.wm.save_mainfile()  # with the box marked
    assert small_copy.cached(str(room), cache) is None
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "room.blend"))
    deadline = time.perf_counter() + 10.0
    while small_copy.cached(str(room), cache) is None and time.perf_counter() < deadline:
        time.sleep(0.01)
    assert small_copy.cached(str(room), cache) is not None


def test_cancel_midway_changes_nothing(room, tmp_path, extension):
    from diminished_reality.operators.support import world_layer

    S = _session(extension)
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    world, settings = bpy.context.scene.world, bpy.context.scene.dimred
    links, report = _links(world), settings.last_report
    image = world_layer.layer_image(world).name
    folder = tmp_path / "dimred"
    files = {p.name: p.read_bytes() for p in folder.iterdir()}

    session = S.RemovalSession.begin(bpy.context)
    session.start()
    # Cancel once the worker is inside the engine (a preview may already show).
    while session.tick(bpy.context) == 'RUNNING' and session.stage in ("starting", "geometry"):
        time.sleep(0.002)
    started = time.perf_counter()
    session.cancel(bpy.context)
    assert time.perf_counter() - started < 1.0
    assert not session.ok and "cancelled" in session.message
    assert _links(world) == links and world_layer.layer_image(world).name == image
    assert settings.last_report == report and [r.object_name for r in settings.removals] == ["Box"]
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == files
    assert S.PREVIEW_IMAGE not in bpy.data.images and S.active() is None


def test_many_remove_cancel_cycles_leave_no_thread_and_no_growth(room, extension):
    S = _session(extension)
    images = len(bpy.data.images)

    def cycle():
        session = S.RemovalSession.begin(bpy.context)
        session.start()
        session.tick(bpy.context)
        session.cancel(bpy.context)

    for _ in range(5):
        cycle()
    gc.collect()
    tracemalloc.start()
    first, _ = tracemalloc.get_traced_memory()
    for _ in range(100):
        cycle()
    gc.collect()
    last, _ = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert not [t for t in threading.enumerate() if t.name == "dimred-worker"]
    assert S.active() is None and len(bpy.data.images) == images
    assert last - first < 1024 * 1024, f"{last - first} bytes kept after 100 cycles"


def test_a_second_run_while_one_runs_is_refused(room, extension):
    from diminished_reality.addon.errors import DimredError

    S = _session(extension)
    session = S.RemovalSession.begin(bpy.context)
    session.start()
    try:
        assert not bpy.ops.dimred.remove.poll()
        with pytest.raises(DimredError, match="already running"):
            S.RemovalSession.begin(bpy.context)
        assert not bpy.ops.dimred.clear.poll()
    finally:
        session.cancel(bpy.context)
    assert bpy.ops.dimred.remove.poll()


def test_undo_after_remove_restores_the_original_world(room, extension):
    from diminished_reality.operators.support import world_layer

    bpy.ops.ed.undo_push(message="before removal")
    # As the UI calls it: a script's operator call pushes an undo step only when asked to.
    assert bpy.ops.dimred.remove('EXEC_DEFAULT', True) == {'FINISHED'}
    assert world_layer.has_layer(bpy.context.scene.world)
    bpy.ops.ed.undo()
    world = bpy.context.scene.world
    assert not world_layer.has_layer(world) and len(world.node_tree.nodes) == 3
    assert len(bpy.context.scene.dimred.removals) == 0
    bpy.ops.ed.redo()
    assert world_layer.has_layer(bpy.context.scene.world)


@pytest.mark.parametrize("storage", ["FILE", "PACK"])
def test_a_second_object_composes_with_the_first(room, tmp_path, extension, storage):
    from diminished_reality.operators.support import world_layer

    settings = bpy.context.scene.dimred
    settings.storage = storage
    tiny_scene.add_crate(bpy, room)
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    settings.target = bpy.data.objects["Crate"]
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    world = bpy.context.scene.world
    assert [r.object_name for r in settings.removals] == ["Box", "Crate"]
    own = {r.object_name: world_layer.image_rgb(r.image) for r in settings.removals}
    assert np.abs(own["Crate"]).max() > 0
    layer = world_layer.image_rgb(world_layer.layer_image(world))
    np.testing.assert_allclose(layer, own["Box"] + own["Crate"], atol=1e-5)
    assert sum(n.type == 'TEX_ENVIRONMENT' for n in world.node_tree.nodes) == 2

    # Removing the first object again replaces its own part and keeps the second's.
    settings.target = bpy.data.objects["Box"]
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    assert [r.object_name for r in settings.removals] == ["Box", "Crate"]
    assert any("Crate" in w for w in json.loads(settings.last_report)["warnings"])
    own = {r.object_name: world_layer.image_rgb(r.image) for r in settings.removals}
    layer = world_layer.image_rgb(world_layer.layer_image(world))
    np.testing.assert_allclose(layer, own["Box"] + own["Crate"], atol=1e-5)

    assert bpy.ops.dimred.clear() == {'FINISHED'}
    assert len(settings.removals) == 0 and not world_layer.has_layer(world)


@pytest.mark.parametrize("storage", ["FILE", "PACK"])
def test_the_result_survives_saving_and_reopening(room, tmp_path, extension, storage):
    from diminished_reality.operators.support import world_layer

    bpy.context.scene.dimred.storage = storage
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    world = bpy.context.scene.world
    shown = world_layer.image_rgb(world_layer.layer_image(world))
    assert (world_layer.layer_image(world).packed_file is not None) == (storage == "PACK")
    assert (tmp_path / "dimred").exists() == (storage == "FILE")
    bpy.ops.wm.save_mainfile()
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "room.blend"))
    world = bpy.context.scene.world
    assert world_layer.has_layer(world)
    np.testing.assert_array_equal(world_layer.image_rgb(world_layer.layer_image(world)), shown)
    assert [r.object_name for r in bpy.context.scene.dimred.removals] == ["Box"]


def test_parameter_overrides_reach_the_engine(room, extension):
    from diminished_reality.addon.quality import PRESETS
    from diminished_reality.operators.settings import OVERRIDABLE

    settings = bpy.context.scene.dimred
    # Untouched, the panel's values are the balanced preset's, so ticking Override changes nothing.
    assert {n: getattr(settings, n) for n in OVERRIDABLE} == pytest.approx(
        {n: getattr(PRESETS["balanced"], n) for n in OVERRIDABLE})
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    assert json.loads(settings.last_report)["parameters"]["patches"] == PRESETS["draft"].patches
    settings.override_parameters = True
    settings.patches, settings.seed = 123, 7
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    used = json.loads(settings.last_report)["parameters"]
    assert used["patches"] == 123 and used["seed"] == 7 and used["working_width"] == PRESETS["balanced"].working_width
    settings.working_width = 512
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    assert json.loads(settings.last_report)["parameters"]["working_width"] == 512
    # An odd width is refused with what to type, and the last result stays.
    last = settings.last_report
    settings.working_width = 1023
    with pytest.raises(RuntimeError, match="working_width must be an even number of pixels, at least 128, not 1023"):
        bpy.ops.dimred.remove()
    assert settings.last_report == last
