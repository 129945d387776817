"""The lat-long mapping's algebra: directions, uv, pixel directions and solid angles, sampling.

That it is the mapping Cycles renders is proven against renders in
`tests/blender/test_latlong_cycles.py`.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from addon.geometry import latlong


def _random_directions(n: int, seed: int = 0) -> np.ndarray:
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def test_direction_uv_round_trip():
    d = _random_directions(1000)
    for rotation in (None, _rotation(1)):
        u, v = latlong.direction_to_uv(d, rotation)
        assert np.all((u >= 0) & (u <= 1) & (v >= 0) & (v <= 1))
        np.testing.assert_allclose(latlong.uv_to_direction(u, v, rotation), d, atol=1e-12)


def test_uv_direction_round_trip_and_axes():
    rng = np.random.default_rng(2)
    u, v = rng.uniform(0.001, 0.999, 500), rng.uniform(0.001, 0.999, 500)
    u2, v2 = latlong.direction_to_uv(latlong.uv_to_direction(u, v))
    np.testing.assert_allclose(u2, u, atol=1e-12)
    np.testing.assert_allclose(v2, v, atol=1e-12)
    # +X is the image centre, +Y left of it (u = 0.25), up is v = 1, the seam is at -X.
    u, v = latlong.direction_to_uv(np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [-1, -1e-9, 0]]))
    np.testing.assert_allclose(u[:3], [0.5, 0.25, 0.5], atol=1e-12)
    np.testing.assert_allclose(v, [0.5, 0.5, 1.0, 0.5], atol=1e-12)
    assert u[3] == pytest.approx(1.0, abs=1e-9)


def test_pixel_directions_are_unit_and_top_row_is_up():
    d = latlong.pixel_directions(16, 8)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0, atol=1e-12)
    assert np.all(d[0, :, 2] > 0.9) and np.all(d[-1, :, 2] < -0.9)


@pytest.mark.parametrize("size", [(8, 4), (64, 32), (2048, 1024)])
def test_pixel_solid_angles_sum_to_the_sphere(size):
    width, height = size
    omega = latlong.pixel_solid_angles(width, height)
    assert omega.shape == (height, 1)
    assert omega.sum() * width == pytest.approx(4.0 * math.pi, rel=1e-12)


def test_uv_to_pixel_wraps_the_seam_and_clamps_the_poles():
    """u wraps (u < 0 is the last column, u = 1 the first); v is clamped (v = 1 is the top row,
    v = 0 the bottom row, not a row past the image)."""
    row, col = latlong.uv_to_pixel(np.array([-0.01, 1.0, 0.5, 0.5]), np.array([0.5, 0.5, 1.0, 0.0]), 8, 4)
    assert row.tolist() == [2, 2, 0, 3]
    assert col.tolist() == [7, 0, 4, 4]
