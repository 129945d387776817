"""The object as the photograph shows it: a window too large for its pixel budget is segmented
on an averaged copy and still marks the object where the panorama shows it."""
from __future__ import annotations

from addon.geometry.mesh import build_geometry
from addon.segmentation.seen import seen_object
from tests.engine import tiny_room


def test_a_window_over_the_pixel_budget_is_segmented_on_a_copy_averaged_over_2x2():
    scene = tiny_room.scene_data(1024, 512)
    geo = build_geometry(scene.triangles, scene.tri_object, scene.object_names, scene.center, scene.rotation)
    box = scene.object_names.index("Box")
    full = seen_object(scene.hdri, geo, box)
    pixels = full.shown.size
    coarse = seen_object(scene.hdri, geo, box, max_pixels=pixels // 2)
    assert (full.factor, coarse.factor) == (1, 2)
    assert coarse.shown.size <= pixels // 4 + 2 * sum(full.shown.shape)
    # Both mark the box's pixels (the red of the synthetic panorama) and little else.
    red = (scene.hdri[..., 0] > 0.45) & (scene.hdri[..., 1] < 0.1)
    for seen in (full, coarse):
        shown = seen.whole(512, 1024)
        assert shown[red].mean() > 0.98
        assert (shown & ~red).sum() < 0.1 * red.sum()
