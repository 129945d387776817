"""The Relocate operator end to end on the tiny room (background mode, so it runs synchronously):
a refused move changes nothing; a relocation writes the layer, moves the object, undoes, redoes
and clears; later removals see the object at its new place; relocating again starts from the
photographed place and replaces the entry; the threaded run the interactive tool starts, and
what the tool does to the object (Blender's modal events need a window, which the bpy module
has not: the input itself is tested in test_relocate_input.py)."""
from __future__ import annotations

import json
import math
from pathlib import Path
from types import SimpleNamespace

import bpy
import numpy as np
import pytest
from mathutils import Matrix, Vector

from tests.blender import tiny_scene

MOVE = (40.0, 1.3)


def _state(tmp_path: Path) -> dict:
    """What a refused run must leave as it was: every file by its bytes, the world's nodes and
    links, the images, the settings and the box's transform."""
    scene = bpy.context.scene
    settings, tree, box = scene.dimred, scene.world.node_tree, bpy.data.objects["Box"]
    return {
        "files": {str(p.relative_to(tmp_path)): p.read_bytes() for p in sorted(tmp_path.rglob("*")) if p.is_file()},
        "nodes": sorted(n.name for n in tree.nodes),
        "links": sorted((link.from_node.name, link.from_socket.identifier, link.to_node.name,
                         link.to_socket.identifier) for link in tree.links),
        "images": sorted(bpy.data.images.keys()),
        "removals": [(r.object_name, r.kind) for r in settings.removals],
        "report": settings.last_report,
        "panel": (settings.yaw, settings.distance_scale),
        "transform": [tuple(getattr(box, name)) for name in ("location", "rotation_euler", "scale")],
        "matrix": [tuple(row) for row in box.matrix_world],
    }


def _expected_matrix(photographed: Matrix, yaw: float, distance_scale: float) -> np.ndarray:
    """Where the move puts the box, from the scene's own numbers (not the engine's report)."""
    from diminished_reality.addon.relocation.fixedview import Move, move_matrix

    lo, hi = np.array(tiny_scene.BOX)
    reference = np.array(photographed) @ np.append(0.5 * (lo + hi), 1.0)
    return move_matrix(np.array(tiny_scene.CENTER), reference[:3], Move(yaw, distance_scale)) @ np.array(photographed)


def _relocate(yaw: float, distance_scale: float) -> set[str]:
    # As the UI calls it: a script's operator call pushes an undo step only when asked to.
    return bpy.ops.dimred.relocate('EXEC_DEFAULT', True, yaw=yaw, distance_scale=distance_scale)


def _own(settings) -> dict[str, np.ndarray]:
    from diminished_reality.operators.support import world_layer

    return {r.object_name: world_layer.image_rgb(r.image) for r in settings.removals}


def _layer() -> np.ndarray:
    from diminished_reality.operators.support import world_layer

    return world_layer.image_rgb(world_layer.layer_image(bpy.context.scene.world))


@pytest.mark.parametrize("yaw, distance_scale, message", [
    (40.0, 0.0, "distance factor must be a positive number"),
    (40.0, -1.3, "distance factor must be a positive number"),
    (40.0, math.nan, "distance factor must be a positive number"),
    # (An infinite yaw cannot be asked for: Blender clamps a float property to the largest float.)
    (math.nan, 1.3, "yaw must be a finite angle"),
])
def test_a_move_breaking_the_constraint_is_refused_and_changes_nothing(room, tmp_path, yaw, distance_scale, message):
    before = _state(tmp_path)
    with pytest.raises(RuntimeError, match=message) as refused:
        _relocate(yaw, distance_scale)
    assert len(str(refused.value).strip().splitlines()) == 1
    assert _state(tmp_path) == before


def test_a_move_into_the_wall_is_refused_by_the_engine_and_changes_nothing(room, tmp_path):
    before = _state(tmp_path)
    with pytest.raises(RuntimeError, match="Box") as refused:
        _relocate(0.0, 2.0)  # the box's centre would reach the wall at x = 2
    assert len(str(refused.value).strip().splitlines()) == 1
    assert _state(tmp_path) == before


def test_relocate_writes_the_layer_moves_the_box_undoes_redoes_and_clears(room, tmp_path, extension):
    from diminished_reality.addon.relocation.fixedview import Move
    from diminished_reality.operators.relocate import Placement
    from diminished_reality.operators.support import world_layer

    box = bpy.data.objects["Box"]
    photographed = box.matrix_world.copy()
    preview = Placement.of_target(bpy.context).matrix(Move(*MOVE))
    bpy.ops.ed.undo_push(message="before relocation")

    assert _relocate(*MOVE) == {'FINISHED'}
    settings = bpy.context.scene.dimred
    assert (tmp_path / "dimred" / "Room_Probe_Box_difference.exr").is_file()
    assert (tmp_path / "dimred" / "Room_Probe_difference.exr").is_file()
    (entry,) = settings.removals
    assert (entry.object_name, entry.kind) == ("Box", 'RELOCATE')
    assert (entry.yaw, entry.distance_scale) == pytest.approx(MOVE)
    assert entry.photographed_matrix() == photographed
    own = _own(settings)["Box"]
    assert np.isfinite(own).all() and np.abs(own).max() > 0
    np.testing.assert_array_equal(_layer(), own)
    relocation = json.loads(settings.last_report)["relocation"]
    assert (relocation["yaw"], relocation["distance_scale"]) == pytest.approx(MOVE)
    # The box stands where the new panorama shows it, which is where the interactive tool put it.
    moved = np.array(box.matrix_world)
    np.testing.assert_allclose(moved, _expected_matrix(photographed, *MOVE), atol=1e-5)
    np.testing.assert_allclose(moved, np.array(preview), atol=1e-5)
    assert (settings.yaw, settings.distance_scale) == pytest.approx(MOVE)

    bpy.ops.ed.undo()
    scene = bpy.context.scene
    assert bpy.data.objects["Box"].matrix_world == photographed
    assert not world_layer.has_layer(scene.world) and len(scene.dimred.removals) == 0
    bpy.ops.ed.redo()
    scene = bpy.context.scene
    np.testing.assert_allclose(np.array(bpy.data.objects["Box"].matrix_world), moved, atol=1e-6)
    assert world_layer.has_layer(scene.world) and [r.kind for r in scene.dimred.removals] == ['RELOCATE']

    assert bpy.ops.dimred.clear() == {'FINISHED'}
    assert not world_layer.has_layer(scene.world) and len(scene.dimred.removals) == 0
    np.testing.assert_allclose(np.array(bpy.data.objects["Box"].matrix_world), np.array(photographed), atol=1e-6)


def test_later_removals_see_the_relocated_object_at_its_new_place(room, extension):
    S = extension.operators.support.session
    settings = bpy.context.scene.dimred
    tiny_scene.add_crate(bpy, room)
    box = bpy.data.objects["Box"]
    photographed = box.matrix_world.copy()
    assert _relocate(*MOVE) == {'FINISHED'}
    moved = box.matrix_world.copy()

    settings.target = bpy.data.objects["Crate"]
    run = S.RemovalSession.begin(bpy.context)
    scene = run.request.scene
    # In the geometry (not left out as removed objects are), at its new place.
    mine = scene.triangles[scene.tri_object == scene.object_index("Box")].reshape(-1, 3)
    corners = np.array(tiny_scene.BOX)
    np.testing.assert_allclose([mine.min(axis=0)[2], mine.max(axis=0)[2]], corners[:, 2], atol=1e-6)
    centre = np.array(moved) @ np.append(0.5 * corners.sum(axis=0), 1.0)
    np.testing.assert_allclose(0.5 * (mine.min(axis=0) + mine.max(axis=0)), centre[:3], atol=1e-5)
    assert run.run_here(bpy.context), run.message

    assert [(r.object_name, r.kind) for r in settings.removals] == [("Box", 'RELOCATE'), ("Crate", 'REMOVE')]
    own = _own(settings)
    np.testing.assert_allclose(_layer(), own["Box"] + own["Crate"], atol=1e-5)
    assert box.matrix_world == moved

    # Removing the relocated object puts it back where the panorama shows it.
    settings.target = box
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    assert [(r.object_name, r.kind) for r in settings.removals] == [("Box", 'REMOVE'), ("Crate", 'REMOVE')]
    np.testing.assert_allclose(np.array(box.matrix_world), np.array(photographed), atol=1e-6)


def test_relocating_again_starts_from_the_photographed_place_and_replaces_the_entry(room, extension, drive):
    from diminished_reality.addon.relocation.fixedview import Move

    S = extension.operators.support.session
    settings = bpy.context.scene.dimred
    box = bpy.data.objects["Box"]
    photographed = box.matrix_world.copy()
    assert _relocate(*MOVE) == {'FINISHED'}

    # The second time as the interactive tool runs it: in a worker thread, polled on a timer.
    run = S.RemovalSession.begin(bpy.context, Move(-20.0, 0.8))
    mine = run.request.scene.triangles[run.request.scene.tri_object == run.request.scene.object_index("Box")]
    np.testing.assert_allclose(mine.reshape(-1, 3).min(axis=0), tiny_scene.BOX[0], atol=1e-5)
    np.testing.assert_allclose(mine.reshape(-1, 3).max(axis=0), tiny_scene.BOX[1], atol=1e-5)
    run.start()
    assert drive(run) == 'FINISHED', run.message
    assert run.message.startswith("Relocated 'Box' (yaw -20.0°, distance ×0.80")

    (entry,) = settings.removals
    assert (entry.kind, entry.yaw, entry.distance_scale) == ('RELOCATE', -20.0, pytest.approx(0.8))
    assert entry.photographed_matrix() == photographed
    np.testing.assert_allclose(np.array(box.matrix_world), _expected_matrix(photographed, -20.0, 0.8), atol=1e-5)
    np.testing.assert_array_equal(_layer(), _own(settings)["Box"])


def test_the_interactive_tool_moves_the_box_and_cancel_restores_it_exactly(room, extension):
    from diminished_reality.addon.relocation.fixedview import Move
    from diminished_reality.operators import relocate
    from diminished_reality.operators.support.relocate_input import RelocateInput

    box = bpy.data.objects["Box"]
    box.rotation_mode = 'XYZ'
    box.rotation_euler = (0.0, 0.0, 0.1234567)
    bpy.context.view_layer.update()
    before = relocate.snapshot(box)
    placement = relocate.Placement.of_target(bpy.context)
    # The operator's own methods, on a stand-in for the running operator (no window here).
    tool = SimpleNamespace(_tool=RelocateInput.starting_at(*MOVE), _placement=placement, _saved=before)
    relocate.DIMRED_OT_relocate._show(tool, bpy.context)
    np.testing.assert_allclose(np.array(box.matrix_world), _expected_matrix(placement.photographed, *MOVE), atol=1e-5)
    assert relocate.snapshot(box) != before
    assert placement.elevation_change(Move(*MOVE)) == pytest.approx(
        math.degrees(math.atan2(-0.9, 1.3) - math.atan2(-0.9, 1.0)), abs=0.05)

    relocate.DIMRED_OT_relocate._end_tool(tool, bpy.context)
    assert relocate.snapshot(box) == before


def test_the_interactive_tool_refuses_to_confirm_a_place_the_engine_would_refuse(room, extension):
    """Checked as the mouse moves: the header says why, and Enter does nothing until the values
    lead to an allowed place."""
    from diminished_reality.operators import relocate
    from diminished_reality.operators.support.relocate_input import RelocateInput

    box = bpy.data.objects["Box"]
    before = relocate.snapshot(box)
    placement = relocate.Placement.of_target(bpy.context)
    tool = SimpleNamespace(_tool=RelocateInput.starting_at(0.0, 2.0), _placement=placement, _saved=before)
    relocate.DIMRED_OT_relocate._show(tool, bpy.context)
    assert "would not stand on its support plane" in tool._tool.refusal
    enter = SimpleNamespace(type="RET", value="PRESS", mouse_x=0, mouse_y=0, shift=False, ctrl=False)
    assert tool._tool.handle(enter) == "NONE"
    tool._tool = RelocateInput.starting_at(*MOVE)
    relocate.DIMRED_OT_relocate._show(tool, bpy.context)
    assert tool._tool.refusal == "" and tool._tool.handle(enter) == "CONFIRM"
    relocate.DIMRED_OT_relocate._end_tool(tool, bpy.context)
    assert relocate.snapshot(box) == before


def _mark_and_move(delta: Matrix) -> bpy.types.Object:
    """Mark the box as the user does (active object, Mark), then move it by the world `delta`."""
    box = bpy.data.objects["Box"]
    bpy.context.view_layer.objects.active = box
    assert bpy.ops.dimred.mark_remove() == {'FINISHED'}
    box.matrix_world = delta @ box.matrix_world
    bpy.context.view_layer.update()
    return box


def _about(point, axis: str, degrees: float) -> Matrix:
    """The rotation by `degrees` about the world `axis` through `point`."""
    return Matrix.Translation(point) @ Matrix.Rotation(math.radians(degrees), 4, axis) @ Matrix.Translation(
        -Vector(point))


def test_relocate_from_the_transform_the_artist_gave(room, extension):
    """Moved by hand about the probe centre's axis (G/R), then Relocate from Transform."""
    box = _mark_and_move(_about(tiny_scene.CENTER, 'Z', -35.0))
    marked = bpy.context.scene.dimred.marked_placement()
    assert bpy.ops.dimred.relocate('EXEC_DEFAULT', True, from_transform=True) == {'FINISHED'}
    settings = bpy.context.scene.dimred
    (entry,) = settings.removals
    assert (entry.kind, entry.yaw, entry.distance_scale) == ('RELOCATE', pytest.approx(-35.0), pytest.approx(1.0))
    assert entry.photographed_matrix() == marked
    np.testing.assert_allclose(np.array(box.matrix_world), _expected_matrix(marked, -35.0, 1.0), atol=1e-5)
    assert json.loads(settings.last_report)["relocation"]["yaw"] == pytest.approx(-35.0)


@pytest.mark.parametrize("case, expected", [
    ("tilt", "tilts the object by 10.0 degrees"),
    ("lift", "lifts the object by +0.250"),
    ("not moved", "stands where the panorama shows it"),
])
def test_relocate_from_a_transform_the_constraint_forbids_changes_nothing(room, tmp_path, case, expected):
    box_centre = 0.5 * (Vector(tiny_scene.BOX[0]) + Vector(tiny_scene.BOX[1]))
    delta = {"tilt": _about(box_centre, 'X', 10.0), "lift": Matrix.Translation((0.0, 0.0, 0.25)),
             "not moved": Matrix.Identity(4)}[case]
    _mark_and_move(delta)
    before = _state(tmp_path)
    with pytest.raises(RuntimeError, match=expected.replace("+", r"\+")) as refused:
        bpy.ops.dimred.relocate('EXEC_DEFAULT', True, from_transform=True)
    assert len(str(refused.value).strip().splitlines()) == 1
    assert _state(tmp_path) == before
