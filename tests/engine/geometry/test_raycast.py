"""Panorama ray casting and ray hits against analytic geometry."""
import numpy as np
import pytest

from addon.geometry.raycast import trace_panorama
from tests.engine.tiny_room import box_triangles as box

ROOM = box([-2.0, -2.5, -1.5], [3.0, 1.5, 1.2])


def test_every_pixel_hits_the_closed_room_at_the_right_distance():
    hits = trace_panorama(ROOM, 128, 64)
    assert (hits.tri >= 0).all()
    p = hits.points.reshape(-1, 3)
    lo, hi = np.array([-2.0, -2.5, -1.5]), np.array([3.0, 1.5, 1.2])
    assert np.minimum(np.abs(p - lo), np.abs(p - hi)).min(axis=1).max() < 1e-9


def test_object_across_the_seam_and_below_the_probe_is_seen_whole():
    seam_box = box([-1.5, -0.3, -1.5], [-1.0, 0.3, -1.0])  # straddles -X, the panorama's seam
    nadir_box = box([-0.2, -0.2, -1.5], [0.2, 0.2, -1.2])  # straight below
    tris = np.concatenate([ROOM, seam_box, nadir_box])
    hits = trace_panorama(tris, 256, 128)
    seen = np.zeros(len(tris), bool)
    seen[np.unique(hits.tri)] = True
    assert hits.tri[:, 0].max() >= 12 and hits.tri[:, -1].max() >= 12  # both sides of the seam
    assert (hits.tri[-1] >= 24).all()  # the bottom row sees the nadir box all around
    assert (hits.tri >= 0).all()


@pytest.mark.parametrize("offset", [0.02, 0.05, 0.11])
def test_an_edge_passing_close_to_a_pole_still_covers_the_rows_beside_it(offset):
    # The ceiling's and floor's diagonals pass `offset` m beside the probe's vertical: between
    # the edge samples the edge climbs rows closer to the pole than any sample, and those rows
    # must still be hit (they were once left empty, a ring of "open room" pixels).
    room = box([-2.0 + offset, -2.0, -1.5], [2.0 + offset, 2.0, 1.2])
    for width in (256, 1024):
        hits = trace_panorama(room, width, width // 2)
        assert (hits.tri >= 0).all(), f"{(hits.tri < 0).sum()} pixels missed at {width}"


def test_a_box_split_into_many_sub_pixel_triangles_is_seen_as_the_box():
    from addon.geometry.patches import split_triangles

    obj = box([-1.4, -0.3, -1.2], [-0.8, 0.3, -0.4])  # across the seam
    fine = split_triangles(obj, 24).reshape(-1, 3, 3)  # 6912 triangles, most smaller than a pixel
    coarse = trace_panorama(np.concatenate([ROOM, obj]), 256, 128)
    split = trace_panorama(np.concatenate([ROOM, fine]), 256, 128)
    np.testing.assert_array_equal(coarse.tri >= 12, split.tri >= 12)
    np.testing.assert_allclose(split.distance, coarse.distance, rtol=1e-9)
    window = trace_panorama(fine, 256, 128, window=(60, 40, 240, 32))
    inside = split.tri[60:100, np.r_[240:256, 0:16]]
    np.testing.assert_array_equal(window.tri, np.where(inside >= 12, inside - 12, -1))
    assert (window.tri >= 0).any() and (window.tri < 0).any()


def test_a_ray_meeting_two_triangles_at_the_same_depth_hits_the_first():
    hits = trace_panorama(np.concatenate([ROOM[:1], ROOM]), 64, 32)
    assert (hits.tri != 1).all() and (hits.tri == 0).any()


def test_first_hits_and_crossings_of_a_unit_cube():
    from addon.geometry.raycast import crossings, first_hits

    cube = box([0.0, 0.0, 0.0], [1.0, 1.0, 1.0])
    origins = np.array([[0.5, 0.5, -1.0], [0.5, 0.5, 0.5], [2.0, 2.0, 0.5]])
    up = np.broadcast_to([0.0, 0.0, 1.0], origins.shape)
    index, t = first_hits(origins, up, cube)
    np.testing.assert_allclose(t[:2], [1.0, 0.5])
    assert t[2] == np.inf and index[2] == -1
    assert set(cube[index[0]][:, 2]) == {0.0} and set(cube[index[1]][:, 2]) == {1.0}
    count = crossings(np.array([[0.3, 0.6, -1.0], [0.3, 0.6, 0.5], [2.0, 2.0, 0.5]]), up, cube)
    assert count.tolist() == [2, 1, 0]


def test_a_projection_taken_once_traces_every_subset_window_and_size_alike():
    from addon.geometry.patches import split_triangles
    from addon.geometry.raycast import project

    fine = split_triangles(box([-1.4, -0.3, -1.2], [-0.8, 0.3, -0.4]), 8).reshape(-1, 3, 3)
    tris = np.concatenate([ROOM, fine, box([-0.2, -0.2, -1.5], [0.2, 0.2, -1.2])])  # across the seam, at the nadir
    edge_on = np.array([[[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.5]]])  # in a plane through the probe
    tris = np.concatenate([tris, edge_on])
    projection = project(tris)
    assert not projection.seen[-1] and projection.seen[:-1].all()
    pick = np.flatnonzero(np.arange(len(tris)) % 3 != 1)
    for width, window in ((64, None), (256, None), (256, (60, 40, 240, 32)), (1024, (400, 112, 900, 300))):
        for subset in (slice(None), pick):
            alone = trace_panorama(tris[subset], width, width // 2, window=window)
            given = trace_panorama(tris[subset], width, width // 2, window=window,
                                   projection=projection.take(subset))
            np.testing.assert_array_equal(given.tri, alone.tri)
            np.testing.assert_array_equal(given.distance, alone.distance)
            np.testing.assert_array_equal(given.bary, alone.bary)


def test_a_projection_in_chunks_of_any_size_is_the_whole_ones(monkeypatch):
    from dataclasses import fields

    from addon.geometry import raycast
    from addon.geometry.patches import split_triangles

    tris = np.concatenate([ROOM, split_triangles(box([-1.4, -0.3, -1.2], [-0.8, 0.3, -0.4]), 4).reshape(-1, 3, 3)])
    whole = raycast.project(tris)
    monkeypatch.setattr(raycast, "_PROJECT_TRIANGLES", 7)  # chunks of 7 triangles, the last one short
    chunked = raycast.project(tris)
    for f in fields(whole):
        np.testing.assert_array_equal(getattr(chunked, f.name), getattr(whole, f.name))
    none = raycast.project(np.zeros((0, 3, 3)))
    assert none.edge_normals.shape == (0, 3, 3) and none.top.shape == (0,)
