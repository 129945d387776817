"""The command line's rough-proxy options through the real engine on the tiny room: `align`
(report, diagnostics picture, --save copy), `remove --align`, `--mask` and its refusals."""
from __future__ import annotations

import json
import os

import bpy
import numpy as np
import pytest
from mathutils import Matrix

from addon.blender import cli
from addon.io.exr import write_png
from tests.blender import tiny_scene

pytestmark = pytest.mark.usefixtures("fresh_blender")

MISPLACED = Matrix.Translation((0.04, -0.03, 0.0))


def _room(folder, *, width: int = 256) -> str:
    """The tiny room at `width` with its box proxy placed 5 cm off the photographed box."""
    hdri = folder / "room.exr"
    tiny_scene.write_exr(hdri, tiny_scene.synthetic_hdri(width, width // 2))
    tiny_scene.build_scene(hdri)
    box = bpy.data.objects["Box"]
    box.matrix_world = MISPLACED @ box.matrix_world
    path = folder / "room.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return str(path)


def test_align_writes_the_correction_the_picture_and_a_corrected_copy(tmp_path, capfd):
    blend = _room(tmp_path)
    before = os.path.getmtime(blend)
    out, copy = tmp_path / "aligned", tmp_path / "copy.blend"
    arguments = ["align", blend, "--object", "Box", "--out", str(out), "--save", str(copy), "--quality", "draft"]
    assert cli.main(arguments) == 0
    stdout, _ = capfd.readouterr()
    assert "aligned 'Box'" in stdout
    assert sorted(os.listdir(out)) == ["diagnostics.png", "report.json"]
    report = json.loads((out / "report.json").read_text())
    alignment = report["alignment"]
    assert alignment["applied"] and alignment["fitted"] == ["shift x", "shift y", "turn", "scale"]
    # The correction undoes the misplacement: about -4 cm in x and +3 cm in y.
    assert alignment["shift_cm"][0] == pytest.approx(-4.0, abs=1.5)
    assert alignment["shift_cm"][1] == pytest.approx(3.0, abs=1.5)
    assert report["segmentation"]["agreement"] > 0.8
    assert os.path.getmtime(blend) == before  # the .blend itself is not touched
    bpy.ops.wm.open_mainfile(filepath=str(copy))
    box = bpy.data.objects["Box"]
    corners = np.array([box.matrix_world @ v.co for v in box.data.vertices])
    photographed = np.array(tiny_scene.BOX)
    # Back where the photograph shows it, to a centimetre at this size (a pixel is 2.5 cm there).
    np.testing.assert_allclose((corners.min(axis=0) + corners.max(axis=0))[:2] / 2,
                               photographed.mean(axis=0)[:2], atol=0.01)


def test_remove_align_reports_the_alignment_and_writes_the_picture(tmp_path):
    blend = _room(tmp_path)
    out = tmp_path / "removed"
    assert cli.main(["remove", blend, "--object", "Box", "--align", "--out", str(out), "--quality", "draft"]) == 0
    assert sorted(os.listdir(out)) == ["diagnostics.png", "difference.exr", "edited.exr", "report.json"]
    report = json.loads((out / "report.json").read_text())
    assert report["alignment"]["applied"] and "alignment" in report["seconds"]
    assert report["segmentation"]["proxy_pixels"] > 0


def test_a_mask_adds_pixels_to_the_region_filled(tmp_path):
    blend = _room(tmp_path)
    mask = np.full((64, 128, 4), 0.5, dtype=np.float32)
    mask[..., 3] = 0.0  # transparent: leaves the region as computed ...
    mask[100 // 2:110 // 2, 20 // 2:30 // 2] = 1.0  # ... but a white patch on the floor adds to it
    path = tmp_path / "mask.png"
    write_png(path, (mask[..., :3] * 255).astype(np.uint8))
    plain, masked = tmp_path / "plain", tmp_path / "masked"
    assert cli.main(["remove", blend, "--object", "Box", "--out", str(plain), "--quality", "draft"]) == 0
    assert cli.main(["remove", blend, "--object", "Box", "--mask", str(path), "--out", str(masked),
                     "--quality", "draft"]) == 0
    hidden = [json.loads((folder / "report.json").read_text())["hidden_pixels"] for folder in (plain, masked)]
    assert hidden[1] > hidden[0]


@pytest.mark.parametrize(("make", "message"), [
    (lambda folder: write_png(folder / "mask.png", np.zeros((50, 90, 3), np.uint8)),
     "is 90x50 but the panorama is 256x128"),
    (lambda folder: (folder / "mask.png").write_bytes(b"not an image"), "not an image Blender can read"),
    (lambda folder: None, "no such mask file"),
])
def test_a_bad_mask_is_refused_with_one_line_and_nothing_written(tmp_path, capfd, make, message):
    blend = _room(tmp_path)
    make(tmp_path)
    out = tmp_path / "out"
    assert cli.main(["remove", blend, "--object", "Box", "--mask", str(tmp_path / "mask.png"), "--out", str(out)]) == 2
    _, stderr = capfd.readouterr()
    lines = [line for line in stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("dimred: error: ") and message in lines[0]
    assert not out.exists()


def test_a_proxy_over_no_object_is_refused_by_align_and_remove(tmp_path, capfd):
    blend = _room(tmp_path)
    bpy.ops.wm.open_mainfile(filepath=blend)
    box = bpy.data.objects["Box"]
    box.matrix_world = Matrix.Translation((-1.7, 0.8, 0.0)) @ box.matrix_world  # onto bare floor
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    for command in ("align", "remove"):
        out = tmp_path / command
        assert cli.main([command, blend, "--object", "Box", "--out", str(out), "--quality", "draft"]) == 2
        _, stderr = capfd.readouterr()
        # Bare floor shows no object there: the message says so rather than a share of object.
        assert ("does not lie over what the photograph shows there (nothing there stands apart from its surroundings"
                in stderr and "paint a mask over it" in stderr and not out.exists())


def test_a_mask_painted_over_what_stands_apart_from_nothing_is_filled(tmp_path, capfd):
    # What the photograph cannot set apart (a dark or noisy picture, an object of the floor's
    # colour; here bare floor) the artist's mask decides: the run goes on and says so.
    blend = _room(tmp_path)
    bpy.ops.wm.open_mainfile(filepath=blend)
    box = bpy.data.objects["Box"]
    box.matrix_world = Matrix.Translation((-1.7, 0.8, 0.0)) @ box.matrix_world
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    mask = np.zeros((128, 256, 3), np.uint8)
    write_png(tmp_path / "black.png", mask)
    mask[64:] = 255  # the floor half of the panorama
    write_png(tmp_path / "floor.png", mask)
    removal = ["remove", blend, "--object", "Box", "--quality", "draft", "--mask"]
    # A mask that only takes pixels away says nothing of where the object is.
    assert cli.main([*removal, str(tmp_path / "black.png"), "--out", str(tmp_path / "black")]) == 2
    assert "nothing there stands apart" in capfd.readouterr().err
    assert cli.main([*removal, str(tmp_path / "floor.png"), "--out", str(tmp_path / "out")]) == 0
    warnings = json.loads((tmp_path / "out" / "report.json").read_text())["warnings"]
    expected = "the photograph does not set 'Box' apart from its surroundings: its proxy's silhouette and the mask are"
    assert [w for w in warnings if w.startswith(expected)] == [expected + " filled"]
