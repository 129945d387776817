"""The quick fill: the object's silhouette against the tracer's, and a fill from the surroundings."""
from __future__ import annotations

import numpy as np
import pytest

from addon.geometry import latlong
from addon.geometry.mesh import to_probe_frame
from addon.geometry.raycast import trace_panorama
from addon.run.quick_preview import push_pull, quick_difference, silhouette
from tests.engine import tiny_room
from tests.engine.tiny_room import box_triangles as box


def _traced(triangles: np.ndarray, width: int, height: int) -> np.ndarray:
    return trace_panorama(triangles, width, height).tri >= 0


@pytest.mark.parametrize("width", [64, 256, 1024])
@pytest.mark.parametrize("corners", [
    ([1.0, -0.3, -1.2], [1.6, 0.3, -0.6]),  # a box on the floor in front
    ([-1.5, -0.3, -0.5], [-1.0, 0.3, 0.5]),  # across the seam at -X
    ([-0.2, -0.2, -1.5], [0.2, 0.2, -1.2]),  # straight below: around the pole
    ([0.05, 0.05, 0.3], [0.25, 0.25, 0.5]),  # close above, beside the pole
])
def test_the_silhouette_is_the_traced_one_up_to_its_edge(width, corners):
    tris = box(*corners)
    mask, traced = silhouette(tris, width, width // 2), _traced(tris, width, width // 2)
    assert traced.any()
    assert not (traced & ~mask).any(), "a pixel that sees the box was missed"
    assert not (mask & ~latlong.dilate(traced, 1)).any(), "a pixel beyond the edge was marked"


@pytest.mark.parametrize("offset", [0.02, 0.05, 0.11])
def test_an_edge_passing_close_to_a_pole_leaves_no_gap(offset):
    # A floor under the probe whose diagonal passes `offset` m beside the vertical: neither of
    # its triangles surrounds the pole, but the rows round it are still covered.
    floor = box([-2.0 + offset, -2.0, -1.5], [2.0 + offset, 2.0, -1.5 + 1e-3])[:2]
    for width in (256, 1024):
        traced = _traced(floor, width, width // 2)
        assert not (traced & ~silhouette(floor, width, width // 2)).any()


def test_many_small_triangles_cover_the_object_they_tile():
    # The box's faces cut into triangles far smaller than a pixel.
    lo, hi = np.array([1.0, -0.3, -1.2]), np.array([1.6, 0.3, -0.6])
    s = np.linspace(0.0, 1.0, 41)
    u, v = np.meshgrid(s[:-1], s[:-1], indexing="ij")
    quads = np.stack([np.stack([u, v], -1), np.stack([u + 0.025, v], -1), np.stack([u + 0.025, v + 0.025], -1),
                      np.stack([u, v + 0.025], -1)], axis=2).reshape(-1, 4, 2)
    pieces = []
    for axis in range(3):
        a, b = [k for k in range(3) if k != axis]
        for side in (lo[axis], hi[axis]):
            points = np.empty((len(quads), 4, 3))
            points[..., axis] = side
            points[..., a] = lo[a] + quads[..., 0] * (hi[a] - lo[a])
            points[..., b] = lo[b] + quads[..., 1] * (hi[b] - lo[b])
            pieces += [points[:, [0, 1, 2]], points[:, [0, 2, 3]]]
    tris = np.concatenate(pieces)
    assert len(tris) == 19200
    mask, traced = silhouette(tris, 256, 128), _traced(box(lo, hi), 256, 128)
    assert not (traced & ~mask).any() and not (mask & ~latlong.dilate(traced, 1)).any()


def test_push_pull_keeps_known_pixels_and_fills_between_them():
    height, width = 32, 64
    ramp = np.broadcast_to(np.linspace(1.0, 2.0, width, dtype=np.float32)[None, :, None], (height, width, 3))
    known = np.ones((height, width), bool)
    known[10:20, 20:30] = False
    filled = push_pull(ramp, known)
    np.testing.assert_array_equal(filled[known], ramp[known])
    hole = filled[~known]
    assert hole.min() >= ramp[:, 19].min() - 1e-6 and hole.max() <= ramp[:, 30].max() + 1e-6
    np.testing.assert_allclose(push_pull(np.full((height, width, 3), 0.7, np.float32), known), 0.7, rtol=1e-6)
    with pytest.raises(ValueError, match="known pixel"):
        push_pull(ramp, np.zeros((height, width), bool))


def test_the_box_is_filled_with_the_floor_around_it():
    scene = tiny_room.scene_data(256, 128)
    mine = scene.tri_object == scene.object_index("Box")
    tris = to_probe_frame(scene.triangles[mine], scene.center, scene.rotation)
    fill = quick_difference(scene.hdri, tris)
    hole = fill.hole
    assert (fill.difference[~hole] == 0).all()
    assert (silhouette(tris, 256, 128) & ~hole).sum() == 0 and hole.sum() > 100
    edited = scene.hdri + fill.difference
    # The box is red (0.5, 0.06, 0.05); the floor and walls around it are grey.
    red = edited[hole, 0] / np.maximum(edited[hole, 1], 1e-6)
    assert np.median(red) < 1.2
