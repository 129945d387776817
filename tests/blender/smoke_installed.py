"""End-to-end test of the built extension, installed the way Blender installs extensions.

`./dev test` runs it twice: from pytest on Blender 5.2 (`tests/test_installed.py`) and as
`.venv311/bin/python tests/smoke_installed.py [ZIP]` on Blender 4.2 LTS (bpy 4.2, Python 3.11,
numpy 1.26), the oldest Blender the manifest claims. It builds the extension zip with that
Blender's own `blender_ext.py` (or takes ZIP), installs and enables it into a throw-away user
profile, and removes the box from a tiny procedural room twice: through the installed package's
`blender -c dimred` command function and through `bpy.ops.dimred.remove`, whose world layer a
Cycles render from the probe centre must show exactly; then undo, redo and clear; and relocates
the box with `bpy.ops.dimred.relocate`, which must move it and clear must put it back.
Each step needs the ones before it, so the first failure ends the run. The closing line is
`smoke: N passed, N failed`; the exit status is non-zero when a step failed.
"""
from __future__ import annotations

import importlib
import importlib.util
import json
import os
import shutil
import sys
import tempfile
import traceback
from collections.abc import Callable
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = "bl_ext.user_default.diminished_reality"
OPERATORS = ("set_probe_center", "mark_remove", "mark_surface", "remove", "relocate", "cancel", "clear", "save_hdri")

# Run as a script: the checkout's root on sys.path makes the test helpers importable as `tests.*`.
sys.path.insert(0, str(ROOT))
from tests.blender import tiny_scene  # noqa: E402


def build_zip(out_dir: Path) -> Path:
    spec = importlib.util.spec_from_file_location("build_extension", ROOT / "scripts" / "build_extension.py")
    build_extension = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(build_extension)
    # This interpreter's bpy validates the manifest for its own Blender version.
    (path,) = build_extension.build(out_dir)
    return path


def install(zip_path: Path) -> None:
    import bpy

    result = bpy.ops.extensions.package_install_files(
        filepath=str(zip_path), repo="user_default", enable_on_install=True
    )
    assert result == {'FINISHED'}, result
    assert PACKAGE in bpy.context.preferences.addons, "the extension was installed but not enabled"
    repo = next(r for r in bpy.context.preferences.extensions.repos if r.module == "user_default")
    installed = Path(repo.directory) / "diminished_reality"
    assert not (installed / "tests").exists() and (installed / "addon" / "geometry" / "latlong.py").is_file()
    # Blender extracts the wheel matching its own Python next to the repositories.
    site = Path(os.environ["BLENDER_USER_RESOURCES"]) / "extensions" / ".local"
    tag = "cpython-{}{}".format(*sys.version_info[:2])
    assert list(site.rglob(f"OpenEXR.{tag}-*.so")), f"no {tag} OpenEXR extracted under {site}"


def registered() -> None:
    import bpy

    for name in OPERATORS:
        assert hasattr(bpy.types, f"DIMRED_OT_{name}"), name
        assert getattr(bpy.ops.dimred, name).get_rna_type().description, name
    assert hasattr(bpy.types.Scene, "dimred")
    assert importlib.import_module(PACKAGE)._cli_handle is not None


def command_function() -> Callable[[list[str]], int]:
    command = importlib.import_module(f"{PACKAGE}.addon.blender.cli").blender_command
    assert callable(command)
    return command


def open_tiny_scene(work: Path) -> tuple[Path, Path]:
    """Write the HDRI and the .blend, then open it as `blender -b SCENE.blend` would."""
    import bpy

    hdri_path = work / "room.exr"
    tiny_scene.write_exr(hdri_path, tiny_scene.synthetic_hdri(64, 32))
    # Not read_homefile/read_factory_settings: those would reload the preferences and with them
    # the list of enabled add-ons.
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    tiny_scene.build_scene(hdri_path)
    blend = work / "room.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    return blend, hdri_path


def check_outputs(out: Path, hdri_path: Path) -> None:
    for name in ("difference.exr", "edited.exr", "report.json"):
        assert (out / name).is_file(), f"{name} was not written"
    hdri = tiny_scene.read_exr(hdri_path)
    difference = tiny_scene.read_exr(out / "difference.exr")
    edited = tiny_scene.read_exr(out / "edited.exr")
    assert difference.shape == edited.shape == hdri.shape, (difference.shape, edited.shape, hdri.shape)
    assert np.isfinite(difference).all() and np.isfinite(edited).all()
    # edited.exr stores the changed pixels to 13 mantissa bits, as the difference
    np.testing.assert_allclose(edited, hdri + difference, rtol=2.0**-13, atol=1e-5)
    assert np.abs(difference).max() > 0, "the difference is zero: nothing was removed"
    report = json.loads((out / "report.json").read_text())
    assert "total" in report["seconds"], report.get("seconds")


def command_run(command: Callable[[list[str]], int], work: Path, hdri_path: Path) -> None:
    out = work / "command"
    center = [str(c) for c in tiny_scene.CENTER]
    code = command(["remove", "--object", "Box", "--out", str(out), "--quality", "draft", "--center", *center])
    assert code == 0, f"exit code {code}"
    check_outputs(out, hdri_path)


def batch_run(command: Callable[[list[str]], int], blend: Path, work: Path, hdri_path: Path) -> None:
    """`blender -c dimred batch` from the installed package: the job in its own process (this
    Python with the installed engine on its path), its folder whole, kept when run again."""
    jobs = work / "jobs.jsonl"
    job = {"id": "room", "blend": str(blend), "op": "remove", "object": "Box",
           "params": {"quality": "draft", "center": list(tiny_scene.CENTER)}}
    jobs.write_text(json.dumps(job) + "\n", encoding="utf-8")
    out = work / "batch"
    for run in ("first", "again"):
        code = command(["batch", str(jobs), "--out", str(out), "--workers", "1"])
        summary = json.loads((out / "summary.json").read_text())
        [record] = summary["records"]
        assert code == 0, f"{run} run: exit code {code}, {record['error']}"
        assert record["status"] == "done" and record["reused"] == (run == "again"), record
    check_outputs(out / "room", hdri_path)


def operator_run(blend: Path, hdri_path: Path) -> None:
    import bpy

    world_layer = importlib.import_module(f"{PACKAGE}.operators.support.world_layer")
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    scene = bpy.context.scene
    settings = scene.dimred
    settings.target = bpy.data.objects["Box"]
    settings.quality = "draft"
    nodes_before = len(scene.world.node_tree.nodes)
    bpy.ops.ed.undo_push(message="before removal")
    # As the UI calls it: a script's operator call pushes an undo step only when asked to.
    assert bpy.ops.dimred.remove('EXEC_DEFAULT', True) == {'FINISHED'}
    assert world_layer.has_layer(scene.world), "Remove did not add the world layer"
    difference = world_layer.image_rgb(world_layer.layer_image(scene.world))
    assert difference.shape == (32, 64, 3) and np.isfinite(difference).all()
    assert np.abs(difference).max() > 0, "the difference is zero: nothing was removed"
    assert json.loads(settings.last_report)["seconds"]

    # What Cycles renders of the world from the probe centre is HDRI + difference.
    edited = tiny_scene.read_exr(hdri_path) + difference
    # The proxy room would hide the world from the camera: only camera rays skip it.
    for obj in scene.objects:
        obj.visible_camera = False
    render = tiny_scene.render_world(64, 32, tiny_scene.CENTER, blend.parent / "world.exr")
    np.testing.assert_allclose(render, edited, rtol=1e-4, atol=1e-4)

    bpy.ops.ed.undo()
    scene = bpy.context.scene
    assert not world_layer.has_layer(scene.world), "undo did not restore the original world"
    assert len(scene.world.node_tree.nodes) == nodes_before
    bpy.ops.ed.redo()
    scene = bpy.context.scene
    assert world_layer.has_layer(scene.world), "redo did not bring the removal back"
    assert bpy.ops.dimred.clear() == {'FINISHED'}
    assert not world_layer.has_layer(scene.world)


def relocate_run(blend: Path) -> None:
    import bpy

    world_layer = importlib.import_module(f"{PACKAGE}.operators.support.world_layer")
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    scene = bpy.context.scene
    scene.dimred.target = box = bpy.data.objects["Box"]
    scene.dimred.quality = "draft"
    photographed = box.matrix_world.copy()
    assert bpy.ops.dimred.relocate(yaw=40.0, distance_scale=1.3) == {'FINISHED'}
    difference = world_layer.image_rgb(world_layer.layer_image(scene.world))
    assert np.isfinite(difference).all() and np.abs(difference).max() > 0, "the relocation changed nothing"
    assert [(r.object_name, r.kind) for r in scene.dimred.removals] == [("Box", 'RELOCATE')]
    # The box's centre (1, 0, 0.3) turned by 40 degrees about the probe's vertical axis, 1.3 times as far.
    corners = np.array([tuple(box.matrix_world @ v.co) for v in box.data.vertices])
    centre = 0.5 * (corners.min(axis=0) + corners.max(axis=0))
    expected = (1.3 * np.cos(np.radians(40.0)), 1.3 * np.sin(np.radians(40.0)), 0.3)
    np.testing.assert_allclose(centre, expected, atol=1e-5)
    assert bpy.ops.dimred.clear() == {'FINISHED'}
    np.testing.assert_allclose(np.array(box.matrix_world), np.array(photographed), atol=1e-6)


def room_run(blend: Path, hdri_path: Path) -> None:
    """Match Room as a user runs it: floor corners clicked on the tiny room's panorama (its
    floor's corners projected to pixels and rounded), the room built, its meshes read back."""
    import bpy

    # The tiny scene without its objects (factory settings would disable the extension).
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    room_builder = importlib.import_module(f"{PACKAGE}.addon.blender.room_builder")
    projection = importlib.import_module(f"{PACKAGE}.addon.roommatch.projection")
    room_builder.show_panorama(bpy.context.scene, str(hdri_path))
    (x0, y0, z0), (x1, y1, _) = tiny_scene.ROOM
    corners = np.array([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])
    probe = np.asarray(tiny_scene.CENTER, dtype=np.float64)
    points = np.concatenate([corners - probe[:2], np.full((4, 1), z0 - probe[2])], axis=1)
    for x, y in np.round(projection.project(points, 64, 32)):
        assert bpy.ops.dimred.room_click(kind='FLOOR', x=float(x), y=float(y)) == {'FINISHED'}
    bpy.context.scene.dimred_room.camera_height = float(probe[2] - z0)
    assert bpy.ops.dimred.match_room() == {'FINISHED'}
    floor = bpy.data.objects["Floor"].data
    assert len(floor.vertices) == 4 and len(bpy.data.objects["Walls"].data.polygons) == 4
    assert "Ceiling" in bpy.data.objects and "Dimred Room Diagnostics" in bpy.data.images
    found = np.array([tuple(v.co) for v in floor.vertices])
    # 64 pixels round the panorama: a whole-pixel click is good to a few degrees only.
    for corner in corners - probe[:2]:
        assert np.min(np.linalg.norm(found[:, :2] - probe[:2] - corner, axis=1)) < 0.25 * np.linalg.norm(corner)


def room_command_run(command: Callable[[list[str]], int], work: Path) -> None:
    """`blender -c dimred room` on the open scene, with the clicks the last step kept on it."""
    import bpy

    clicks = work / "room_clicks.json"
    clicks.write_text(bpy.context.scene["dimred_room_clicks"])
    saved, out = work / "room_copy.blend", work / "room_out"
    assert command(["room", "--clicks", str(clicks), "--save", str(saved), "--out", str(out)]) == 0
    assert saved.is_file() and sorted(p.name for p in out.iterdir()) == ["room.json", "room_diagnostics.png"]
    assert json.loads((out / "room.json").read_text())["room"]["camera_height_m"] == 1.2


def main(argv: list[str]) -> int:
    work = Path(tempfile.mkdtemp(prefix="dimred-smoke-"))
    # Before bpy is imported: Blender reads its user folders once, at start-up.
    os.environ["BLENDER_USER_RESOURCES"] = str(work / "user")
    import bpy

    print(f"smoke: Blender {bpy.app.version_string}, Python {sys.version.split()[0]}, numpy {np.__version__}",
          flush=True)
    passed = failed = 0

    def step(name: str, fn: Callable, *args):
        nonlocal passed, failed
        try:
            value = fn(*args)
        except Exception:
            failed += 1
            print(f"FAIL {name}\n{traceback.format_exc()}", flush=True)
            raise
        passed += 1
        print(f"ok   {name}", flush=True)
        return value

    try:
        zip_path = (Path(argv[0]).resolve() if argv
                    else step("build the zip with this Blender's blender_ext", build_zip, work))
        step("install and enable the zip", install, zip_path)
        step("operators and command registered", registered)
        command = step("blender_command importable from the installed package", command_function)
        blend, hdri_path = step("tiny scene opened", open_tiny_scene, work)
        step("blender -c dimred remove: files written and finite", command_run, command, work, hdri_path)
        step("blender -c dimred batch: the job in its own process, kept when run again", batch_run, command, blend,
             work, hdri_path)
        step("bpy.ops.dimred.remove, Cycles render of the world, undo, redo, clear", operator_run, blend, hdri_path)
        step("bpy.ops.dimred.relocate: the box moved and the layer written, clear puts it back", relocate_run, blend)
        step("bpy.ops.dimred.room_click and match_room: Floor, Walls and Ceiling read back", room_run, blend,
             hdri_path)
        step("blender -c dimred room: the room saved in a copy, room.json and its picture", room_command_run,
             command, work)
    except Exception:
        pass  # step() printed it; every later step depends on this one
    if failed:
        print(f"smoke: files kept in {work}", flush=True)
    else:
        shutil.rmtree(work, ignore_errors=True)
    # flushed now: Blender's exit handler may end the process before Python flushes its buffers
    print(f"smoke: {passed} passed, {failed} failed", flush=True)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
