"""The artist's mask and the diagnostics picture through the operators on the tiny room: a mask
of the wrong size refuses the removal and changes nothing; a new mask leaves the region filled
as it is until white is painted on it, which adds to it; after a removal the diagnostics picture
is an image (and a file beside the difference) that Show Diagnostics puts into an Image Editor."""
from __future__ import annotations

import json
from pathlib import Path

import bpy
import numpy as np
import pytest


def _state(tmp_path: Path) -> dict:
    """What a refused run must leave as it was."""
    scene = bpy.context.scene
    settings, tree = scene.dimred, scene.world.node_tree
    return {
        "files": sorted(str(p.relative_to(tmp_path)) for p in tmp_path.rglob("*")),
        "nodes": sorted(n.name for n in tree.nodes),
        "links": sorted((link.from_node.name, link.to_node.name) for link in tree.links),
        "images": sorted(bpy.data.images.keys()),
        "settings": (settings.last_report, settings.photo_fit, len(settings.removals), settings.mask_image.name),
    }


def _paint(image: bpy.types.Image, rows: slice, cols: slice, value: float) -> None:
    """Paint an opaque grey `value` over rows and columns counted from the top."""
    width, height = image.size
    pixels = np.empty(width * height * 4, np.float32)
    image.pixels.foreach_get(pixels)
    top_first = pixels.reshape(height, width, 4)[::-1]
    top_first[rows, cols] = (value, value, value, 1.0)
    image.pixels.foreach_set(top_first[::-1].ravel())


def _hidden_pixels() -> int:
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    return json.loads(bpy.context.scene.dimred.last_report)["hidden_pixels"]


def test_a_mask_of_the_wrong_size_is_refused_and_changes_nothing(room, tmp_path):
    bpy.context.scene.dimred.mask_image = bpy.data.images.new("Half", 32, 32, alpha=True)
    before = _state(tmp_path)

    with pytest.raises(RuntimeError, match="is 32x32 but the panorama is 64x32") as refused:
        bpy.ops.dimred.remove()

    assert len(str(refused.value).strip().splitlines()) == 1
    assert _state(tmp_path) == before


def test_a_new_mask_leaves_the_region_and_painted_white_adds_to_it(room):
    from diminished_reality.addon.geometry import latlong
    from tests.blender import tiny_scene

    plain = _hidden_pixels()
    assert bpy.ops.dimred.new_mask() == {'FINISHED'}
    mask = bpy.context.scene.dimred.mask_image
    assert tuple(mask.size) == (64, 32)
    assert _hidden_pixels() == plain  # transparent: the region as computed

    # A patch of floor between the probe's foot and the box, outside the region the box hides.
    floor = np.array([0.4, 0.0, 0.0]) - np.array(tiny_scene.CENTER)
    row, col = (int(i) for i in latlong.uv_to_pixel(*latlong.direction_to_uv(floor), 64, 32))
    _paint(mask, slice(row - 1, row + 2), slice(col - 1, col + 2), 1.0)
    assert _hidden_pixels() >= plain + 9


def test_the_diagnostics_picture_is_an_image_a_file_and_shows_in_an_image_editor(room, tmp_path):
    from diminished_reality.operators.support import pictures

    assert not bpy.ops.dimred.show_diagnostics.poll()
    assert bpy.ops.dimred.remove() == {'FINISHED'}

    image = bpy.data.images[pictures.DIAGNOSTICS_IMAGE]
    assert image.packed_file is not None and not image.is_dirty  # nothing to save on quit
    shown = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(shown)
    written = bpy.data.images.load(str(tmp_path / "dimred" / "Room_Probe_Box_diagnostics.png"))
    assert tuple(written.size) == tuple(image.size) and image.size[0] >= 512
    on_disk = np.empty(len(written.pixels), np.float32)
    written.pixels.foreach_get(on_disk)
    np.testing.assert_array_equal(shown, on_disk)  # the same picture, the same way up
    colours = {tuple(c) for c in np.unique(shown.reshape(-1, 4)[:, :3], axis=0)}
    assert {(0.0, 1.0, 1.0), (1.0, 1.0, 0.0)} <= colours  # the proxy's and the photographed outline

    # Background mode has no window to open: the picture stays an image.
    assert bpy.ops.dimred.show_diagnostics() == {'FINISHED'}
    area = bpy.context.window_manager.windows[0].screen.areas[0]
    area.type = 'IMAGE_EDITOR'
    assert bpy.ops.dimred.show_diagnostics() == {'FINISHED'}
    assert area.spaces.active.image == image

    # A second run updates the same image in place, so the editor follows it.
    assert bpy.ops.dimred.remove() == {'FINISHED'}
    assert area.spaces.active.image == bpy.data.images[pictures.DIAGNOSTICS_IMAGE]
    assert [name for name in bpy.data.images.keys() if name.startswith(pictures.DIAGNOSTICS_IMAGE)] == [
        pictures.DIAGNOSTICS_IMAGE]


def test_the_panel_shows_the_fit_and_the_mask(room):
    from diminished_reality.panels import sidebar
    from tests.blender.test_registration import _draw

    assert bpy.ops.dimred.remove() == {'FINISHED'}
    agreement = json.loads(bpy.context.scene.dimred.last_report)["segmentation"]["agreement"]
    drawn = _draw(sidebar.DIMRED_PT_main, bpy.context)
    assert f"label Box: {100 * agreement:.0f} % of the outline agrees" in drawn
    assert {"operator dimred.align", "operator dimred.show_diagnostics", "prop align_first", "prop fit_height"} <= set(
        drawn)

    bpy.context.scene.dimred.photo_fit = json.dumps({"object": "Box", "segmentation": None, "alignment": {
        "applied": True, "shift_cm": [3.0, -4.0, 0.0], "turn_deg": -2.96, "scale_percent": 0.5}})
    assert "label Aligned: 5.0 cm, -3.0°, +0.5 %" in _draw(sidebar.DIMRED_PT_main, bpy.context)
