"""`dimred room`: a click file in, the room's meshes in a saved .blend and room.json with
room_diagnostics.png out; bad clicks are one error line, exit status 2 and nothing written."""
from __future__ import annotations

import json
import os
from pathlib import Path

import bpy
import numpy as np
import pytest

from addon.blender import cli
from addon.io.exr import write_exr
from tests.engine.roommatch.room_truth import clicks_of, distance_errors, flat_panorama, floor_points

pytestmark = pytest.mark.usefixtures("fresh_blender")

W, H = 512, 256
BOX = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
PROBE = np.array([0.0, 0.0, 1.5])


@pytest.fixture
def files(tmp_path: Path) -> tuple[Path, Path]:
    """The panorama of the box room and its click file."""
    panorama = tmp_path / "room.exr"
    write_exr(panorama, flat_panorama(BOX, 2.6, PROBE, W, H))
    floor = clicks_of(floor_points(BOX), PROBE, W, H)
    ceiling = clicks_of(np.array([[3.0, 0.5, 2.6]]), PROBE, W, H)[0]
    clicks = tmp_path / "clicks.json"
    clicks.write_text(json.dumps({"width": W, "height": H, "floor": floor.tolist(), "ceiling": ceiling.tolist(),
                                  "camera_height": 1.5, "manhattan": True}))
    return panorama, clicks


def _vertices(name: str) -> np.ndarray:
    mesh = bpy.data.objects[name].data
    out = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", out)
    return out.reshape(-1, 3)


def test_room_from_an_empty_scene(files, tmp_path: Path, capfd) -> None:
    panorama, clicks = files
    saved, out = tmp_path / "room.blend", tmp_path / "out"
    code = cli.main(["room", "--clicks", str(clicks), "--panorama", str(panorama), "--save", str(saved),
                     "--out", str(out)])
    stdout, stderr = capfd.readouterr()
    assert code == 0, stderr
    # Blender itself says it saved the copy; the command's own line comes last.
    assert stdout.splitlines()[-1].startswith("dimred: matched the room: 4 corners, camera 1.500 m") and stderr == ""
    assert sorted(os.listdir(out)) == ["room.json", "room_diagnostics.png"]
    report = json.loads((out / "room.json").read_text())
    assert report["room"]["ceiling_from"] == "click"
    floor_offsets = [v for k, v in report["photo_edges"]["edge_offsets_px"].items() if k.startswith("floor")]
    assert max(floor_offsets) < 1.0

    bpy.ops.wm.open_mainfile(filepath=str(saved), load_ui=False)
    floor = _vertices("Floor")
    found = floor[[int(np.argmin(np.linalg.norm(floor[:, :2] - c, axis=1))) for c in BOX], :2]
    assert distance_errors(found, BOX, PROBE).max() < 0.02
    assert _vertices("Ceiling")[:, 2] == pytest.approx(2.6, rel=0.03)
    assert len(bpy.data.objects["Walls"].data.polygons) == 4
    assert tuple(bpy.data.objects["ProbeCenter"].location) == pytest.approx((0.0, 0.0, 1.5))
    assert json.loads(bpy.context.scene["dimred_room_clicks"])["floor"] == json.loads(clicks.read_text())["floor"]


def test_room_into_the_open_file(files, tmp_path: Path) -> None:
    from addon.blender import room_builder

    panorama, clicks = files
    room_builder.show_panorama(bpy.context.scene, str(panorama))
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "scene.blend"))
    saved = tmp_path / "with_room.blend"
    assert cli.blender_command(["room", "--clicks", str(clicks), "--snap", "--camera-height", "3.0",
                                "--save", str(saved), "--out", str(tmp_path / "out")]) == 0
    bpy.ops.wm.open_mainfile(filepath=str(saved), load_ui=False)
    assert _vertices("Floor")[:, 0].min() == pytest.approx(-4.0, abs=0.08)  # twice the height: twice the room


def test_objects_of_the_click_file(tmp_path: Path) -> None:
    from addon.roommatch.object_box import BoxFit
    from tests.engine.roommatch.room_truth import with_box

    # Two boxes on the floor: one clicked inside, one by its four feet.
    chair = np.array([1.8, 0.6, np.log(0.8), np.log(0.7), np.log(0.9), np.radians(20.0)])
    table = np.array([-1.0, 1.5, np.log(0.6), np.log(0.6), np.log(0.7), 0.0])
    panorama = tmp_path / "objects.exr"
    write_exr(panorama, with_box(with_box(flat_panorama(BOX, 2.6, PROBE, 1024, 512), chair, 1.5, (0.7, 0.6, 0.1)),
                                 table, 1.5, (0.2, 0.3, 0.8)))
    feet = BoxFit(np.array([-1.0, 1.5, 0.0]), np.array([0.6, 0.6, 0.0]), 0.0, 0.0, 0).corners()[:4]
    clicks = tmp_path / "clicks.json"
    clicks.write_text(json.dumps({
        "width": 1024, "height": 512, "floor": clicks_of(floor_points(BOX), PROBE, 1024, 512).tolist(),
        "camera_height": 1.5, "objects": [
            {"name": "Chair", "click": clicks_of(np.array([[1.8, 0.6, 0.45]]), PROBE, 1024, 512)[0].tolist()},
            {"name": "Table", "footprint": clicks_of(feet, PROBE, 1024, 512).tolist()}]}))
    saved, out = tmp_path / "room.blend", tmp_path / "out"
    assert cli.main(["room", "--clicks", str(clicks), "--panorama", str(panorama), "--save", str(saved),
                     "--out", str(out)]) == 0
    report = json.loads((out / "room.json").read_text())
    assert [(o["name"], o["shape"]) for o in report["objects"]] == [("Chair", "box"), ("Table", "footprint prism")]
    assert all(o["agreement"] >= 0.95 for o in report["objects"])
    bpy.ops.wm.open_mainfile(filepath=str(saved), load_ui=False)
    assert _vertices("Chair")[:, 2].max() == pytest.approx(0.9, rel=0.08)
    assert _vertices("Table")[:, 2].max() == pytest.approx(0.7, rel=0.05)


@pytest.mark.parametrize(("change", "expected"), [
    ({"floor": [[10, 200], [20, 200]]}, "a floor needs 3 or more corners, 2 clicked"),
    ({"camera_height": 0}, "the camera height must be above 0 m"),
    ({"floor_1": [300, 60]}, "floor corner 1 (300, 60) is not below the horizon"),
    ({"floor_1": [600, 200]}, "floor corner 1 (600, 200) lies outside the 512 × 256 panorama"),
    ({"swap": True}, "crosses itself"),
])
def test_bad_clicks_write_nothing(files, tmp_path: Path, capfd, change: dict, expected: str) -> None:
    panorama, clicks = files
    data = json.loads(clicks.read_text())
    if "swap" in change:
        data["floor"][1], data["floor"][2] = data["floor"][2], data["floor"][1]
        data["manhattan"] = False
    elif "floor_1" in change:
        data["floor"][1] = change["floor_1"]
    else:
        data.update(change)
    clicks.write_text(json.dumps(data))
    saved, out = tmp_path / "room.blend", tmp_path / "out"
    code = cli.main(["room", "--clicks", str(clicks), "--panorama", str(panorama), "--save", str(saved),
                     "--out", str(out)])
    stdout, stderr = capfd.readouterr()
    assert code == 2 and stdout == ""
    lines = stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("dimred: error: ") and expected in lines[0], lines
    assert not saved.exists() and not out.exists()
