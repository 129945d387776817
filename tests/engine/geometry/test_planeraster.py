"""Plane rasters: axes, extent, the visible/hidden flags against an analytic occlusion, lookups."""
import numpy as np
import pytest

from addon.geometry import latlong
from addon.geometry import planeraster as PR
from addon.geometry.raycast import trace_panorama
from tests.engine.geometry.test_raycast import box

FLOOR_Z = -1.0
# The floor of a 6 x 6 m room, a 0.2 m square lid at half the probe's height: seen from the
# probe (the origin) the lid hides the floor square [0.8, 1.2]^2 exactly (central projection x2).
FLOOR = np.array([[[-3, -3, FLOOR_Z], [3, -3, FLOOR_Z], [3, 3, FLOOR_Z]],
                  [[-3, -3, FLOOR_Z], [3, 3, FLOOR_Z], [-3, 3, FLOOR_Z]]], float)
LID = np.array([[[0.4, 0.4, -0.5], [0.6, 0.4, -0.5], [0.6, 0.6, -0.5]],
                [[0.4, 0.4, -0.5], [0.6, 0.6, -0.5], [0.4, 0.6, -0.5]]])
WALLS = box([-3, -3, FLOOR_Z], [3, 3, 2.0])[2:]  # the room box without its floor


def maps(width=512):
    tris = np.concatenate([FLOOR, WALLS, LID])
    surface = np.r_[np.zeros(2), np.arange(1, len(WALLS) + 1), np.full(2, 99)].astype(int)
    with_obj = trace_panorama(tris, width, width // 2)
    without = trace_panorama(tris[:-2], width, width // 2)

    def sid(hits):
        return np.where(hits.tri >= 0, surface[np.maximum(hits.tri, 0)], -1)

    s_with = sid(with_obj)
    return s_with, with_obj.distance, sid(without), without.distance, s_with == 99


@pytest.mark.parametrize("normal", [(0, 0, 1), (0, 1, 0), (1, 0, 0), (0.3, -0.5, 0.8)])
def test_axes_are_orthonormal_and_span_the_plane(normal):
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    u, v = PR.plane_axes(n)
    basis = np.stack([u, v, n])
    assert np.allclose(basis @ basis.T, np.eye(3), atol=1e-12)
    if abs(n[2]) < 0.9:
        assert abs(u[2]) < 1e-12  # a wall's rows run horizontally


def test_walls_are_the_planes_with_a_level_normal():
    assert PR.is_wall(np.array([1.0, 0.0, 0.0])) and PR.is_wall(np.array([0.0, -0.9, 0.3]))
    assert not PR.is_wall(np.array([0.0, 0.0, 1.0])) and not PR.is_wall(np.array([0.3, 0.0, -0.95]))
    # a normal need not be of unit length
    assert PR.is_wall(np.array([0.0, 3.0, 1.0])) and not PR.is_wall(np.array([0.0, 1.0, 3.0]))


def test_raster_covers_the_hole_with_its_margin_and_respects_the_cell_budget():
    pts = np.array([[0.8, 0.8, FLOOR_Z], [1.2, 1.2, FLOOR_Z]])
    r = PR.build_raster(np.array([0, 0, 1.0]), pts, cell=0.01, margin=1.0, max_cells=10**6)
    assert r.cell == 0.01
    assert r.shape == (120, 120)  # 0.4 m hole + 0.4 m each side
    row, col = r.coords(pts)
    assert np.all((row > 35) & (row < 85) & (col > 35) & (col < 85))
    centre = r.points()[60, 60]
    assert abs(centre[2] - FLOOR_Z) < 1e-12
    assert np.allclose(r.coords(r.points()[[3, 70], [5, 9]]), ([3, 70], [5, 9]))
    small = PR.build_raster(np.array([0, 0, 1.0]), pts, cell=0.001, margin=1.0, max_cells=100 * 100)
    assert small.shape[0] * small.shape[1] <= 101 * 101 and small.cell > 0.001


def classified_floor(corner_lo, corner_hi, margin, surface=0):
    """A floor raster around the square between two corners, and its flags."""
    pts = np.array([[corner_lo, corner_lo, FLOOR_Z], [corner_hi, corner_hi, FLOOR_Z]])
    r = PR.build_raster(np.array([0, 0, 1.0]), pts, cell=0.02, margin=margin, max_cells=10**6)
    return r, PR.classify(r, *maps(), surface=surface, tolerance=0.02)


def test_classify_finds_the_floor_the_lid_hides():
    r, flags = classified_floor(0.8, 1.2, margin=1.0)
    p = r.points()
    inside = (np.abs(p[..., 0] - 1.0) < 0.15) & (np.abs(p[..., 1] - 1.0) < 0.15)
    outside = (np.abs(p[..., 0] - 1.0) > 0.27) | (np.abs(p[..., 1] - 1.0) > 0.27)
    assert (flags[inside] == PR.HIDDEN).all()
    assert (flags[outside] == PR.SEEN).all()
    # Seen from the wall's side, no floor cell is on the wall.
    _, wall = classified_floor(0.8, 1.2, margin=1.0, surface=1)
    assert (wall == PR.OTHER).all()


def test_cells_beyond_the_surface_are_other():
    r, flags = classified_floor(2.6, 2.9, margin=2.0)
    p = r.points()
    beyond = (p[..., 0] > 3.0) | (p[..., 1] > 3.0)
    far_beyond = (p[..., 0] > 3.4) | (p[..., 1] > 3.4)
    # Near the edge a grazing pixel's footprint spans ~20 cm: only one pixel's fuzz is allowed.
    assert far_beyond.any() and (flags[far_beyond] == PR.OTHER).all()
    assert (flags[beyond] == PR.OTHER).mean() > 0.8
    assert (flags[~beyond] != PR.OTHER).mean() > 0.95


def test_panorama_lookup_ignores_invalid_pixels():
    image = np.zeros((64, 128, 3))
    image[..., 0] = 2.0
    valid = np.ones((64, 128), bool)
    valid[:, 60:] = False
    image[:, 60:] = 1e6  # must never leak into the values
    r = PR.build_raster(np.array([0, 0, 1.0]), np.array([[-1.0, -0.5, FLOOR_Z], [1.0, 0.5, FLOOR_Z]]),
                        cell=0.05, margin=0.2, max_cells=10**6)
    values, weight = PR.sample_panorama(r, image, valid)
    ok = weight > 0
    assert ok.any() and (~ok).any()
    assert np.allclose(values[ok, 0], 2.0) and values.max() < 2.0 + 1e-9


def test_raster_lookup_is_bilinear():
    r = PR.PlaneRaster(origin=np.zeros(3), u=np.array([1.0, 0, 0]), v=np.array([0, 1.0, 0]), cell=0.1, shape=(4, 5))
    rows, cols = np.mgrid[0:4, 0:5]
    image = np.stack([3.0 * rows + cols], axis=-1).astype(float)
    pts = np.array([[0.05 + 0.1 * 1.25, 0.05 + 0.1 * 2.5, 0.0], [0.0, 0.0, 0.0], [9.0, 9.0, 0.0]])
    got = PR.sample_raster(r, image, pts)[:, 0]
    assert np.allclose(got, [3 * 2.5 + 1.25, 0.0, 3 * 3 + 4])  # inside, clamped low, clamped high


def _points_between_pixels(width: int, height: int, rng: np.random.Generator, n: int) -> np.ndarray:
    """Directions at random sub-pixel positions, away from the poles and the seam."""
    x = rng.uniform(8, width - 8, n)
    y = rng.uniform(8, height - 8, n)
    return latlong.uv_to_direction((x + 0.5) / width, 1.0 - (y + 0.5) / height)


def test_lookup_keeping_grain_keeps_a_pixels_spread_where_bilinear_halves_it():
    rng = np.random.default_rng(3)
    image = 1.0 + 0.1 * rng.standard_normal((128, 256, 3))
    valid = np.ones((128, 256), bool)
    pts = _points_between_pixels(256, 128, rng, 20000)
    plain, _ = PR.sample_points(pts, image, valid)
    kept, weight = PR.sample_points_keeping_grain(pts, image, valid)
    assert (weight > 0.999).all()
    assert 0.55 < plain.std() / image.std() < 0.8  # bilinear averages the grain away
    assert 0.88 < kept.std() / image.std() < 1.07
    assert abs(kept.mean() - 1.0) < 0.005



def test_lookup_keeping_grain_is_the_same_in_chunks_of_any_size(monkeypatch):
    # The points are looked up in chunks side by side: the chunks' answers are the whole's.
    rng = np.random.default_rng(6)
    image = 1.0 + 0.1 * rng.standard_normal((64, 128, 3))
    valid = rng.random((64, 128)) > 0.1
    pts = _points_between_pixels(128, 64, rng, 1000).reshape(10, 100, 3)
    whole, w_whole = PR.sample_points_keeping_grain(pts, image, valid)
    monkeypatch.setattr(PR, "_GRAIN_POINTS", 37)  # 28 chunks, the last one short
    chunked, w_chunked = PR.sample_points_keeping_grain(pts, image, valid)
    assert whole.shape == (10, 100, 3) and w_whole.shape == (10, 100)
    assert np.array_equal(whole, chunked) and np.array_equal(w_whole, w_chunked)
    empty, w_empty = PR.sample_points_keeping_grain(np.zeros((0, 3)), image, valid)
    assert empty.shape == (0, 3) and w_empty.shape == (0,)

def test_lookup_keeping_grain_interpolates_a_smooth_image_as_bilinear_does():
    rows, cols = np.mgrid[0:128, 0:256].astype(float)
    image = np.stack([0.5 + 0.01 * rows + 0.003 * cols, 0.2 + 0.002 * cols, np.full_like(rows, 0.7)], axis=-1)
    valid = np.ones((128, 256), bool)
    valid[40:50] = False  # the mean around a pixel is taken over valid pixels only
    pts = _points_between_pixels(256, 128, np.random.default_rng(4), 2000)
    plain, w0 = PR.sample_points(pts, image, valid)
    kept, w1 = PR.sample_points_keeping_grain(pts, image, valid)
    row = (1.0 - latlong.direction_to_uv(pts)[1]) * 128 - 0.5
    ok = (w0 > 0.999) & ((row < 37) | (row > 52))  # beside the band the valid mean is one-sided
    assert np.array_equal(w0, w1) and ok.mean() > 0.7
    # a plane is its own local mean, so the deviations scaled up are zero
    assert np.abs(kept[ok] - plain[ok]).max() < 1e-9


@pytest.mark.parametrize("degrees", [0.0, 20.0, 70.0, -35.0])
def test_edge_direction_follows_a_rotated_floor_not_its_diagonal(degrees):
    # A 5 x 3 m floor as two triangles, turned about the vertical: its sides vote for its
    # orientation (modulo 90 degrees); the diagonal each triangle shares must not tilt it.
    a = np.radians(degrees)
    rot = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    corners = np.array([[0, 0, 0], [5, 0, 0], [5, 3, 0], [0, 3, 0]], dtype=float) @ rot.T
    triangles = np.stack([corners[[0, 1, 2]], corners[[0, 2, 3]]])
    got = PR.edge_direction(triangles, np.array([0.0, 0.0, 1.0]))
    angle = np.degrees(np.arctan2(got[1], got[0]))
    assert abs((angle - degrees + 45.0) % 90.0 - 45.0) < 0.01
    u, v = PR.plane_axes(np.array([0.0, 0.0, 1.0]), got)
    # The raster's columns run along one of the floor's sides.
    assert abs(u @ v) < 1e-12
    assert max(abs(u @ rot[:, 0]), abs(u @ rot[:, 1])) == pytest.approx(1.0, abs=1e-9)


def test_lookup_keeping_grain_on_a_window_across_the_seam_equals_the_whole_panoramas():
    rng = np.random.default_rng(5)
    image = 1.0 + 0.1 * rng.standard_normal((64, 128, 3))
    valid = rng.random((64, 128)) > 0.1
    # a window of rows 20-43 and columns 100-127 then 0-19, wrapping around the seam
    frame = PR.Frame(20, 100, 64, 128)
    cols = np.r_[100:128, 0:20]
    window, window_valid = image[20:44][:, cols], valid[20:44][:, cols]
    u = (np.r_[rng.uniform(102, 127.5, 300), rng.uniform(0, 18, 300)] + 0.5) / 128
    v = 1.0 - (rng.uniform(22, 41, 600) + 0.5) / 64
    pts = latlong.uv_to_direction(u, v)
    whole, w_whole = PR.sample_points_keeping_grain(pts, image, valid)
    part, w_part = PR.sample_points_keeping_grain(pts, window, window_valid, frame=frame)
    assert np.allclose(w_whole, w_part) and np.allclose(whole, part)
