"""Analytic point-to-triangle form factors against closed forms, at contact and at the horizon."""
import numpy as np
import pytest

from addon.light.formfactor import paired_point_to_triangle, point_to_triangle

UP = np.array([[0.0, 0.0, 1.0]])
ORIGIN = np.zeros((1, 3))


def rect(p0, e1, e2):
    p0, e1, e2 = (np.asarray(v, dtype=float) for v in (p0, e1, e2))
    return np.array([[p0, p0 + e1, p0 + e1 + e2], [p0, p0 + e1 + e2, p0 + e2]])


def corner_rectangle(x, y):
    """Differential area to a parallel rectangle at unit height with a corner above it."""
    a, b = np.sqrt(1 + x * x), np.sqrt(1 + y * y)
    return (x / a * np.arctan(y / a) + y / b * np.arctan(x / b)) / (2 * np.pi)


@pytest.mark.parametrize(("size", "rel"), [(0.01, 1e-5), (0.1, 2e-3), (1.0, 1e-9), (10.0, 1e-9)])
def test_parallel_square_matches_closed_form(size, rel):
    """Exact near (the contour), within (radius / distance)^3 far away (the edge midpoints)."""
    tris = rect([-size / 2, -size / 2, 1.0], [size, 0, 0], [0, size, 0])
    f = point_to_triangle(ORIGIN, UP, tris).sum()
    assert f == pytest.approx(4 * corner_rectangle(size / 2, size / 2), rel=rel)


@pytest.mark.parametrize("gap", [1e-1, 1e-3, 1e-6])
def test_touching_wall_stays_finite_and_tends_to_half(gap):
    wall = rect([0, -1e4, 0], [0, 2e4, 0], [0, 0, 1e4])
    f = point_to_triangle(np.array([[gap, 0, 0]]), UP, wall).sum()
    assert np.isfinite(f) and f == pytest.approx(0.5, abs=gap + 1e-6)


def test_horizon_clipping_drops_the_part_below():
    below_and_above = rect([0, -1, -1], [0, 2, 0], [0, 0, 2])
    above = rect([0, -1, 0], [0, 2, 0], [0, 0, 1])
    x = np.array([[0.3, 0, 0]])
    assert point_to_triangle(x, UP, below_and_above).sum() == pytest.approx(point_to_triangle(x, UP, above).sum())


def test_one_sided_senders_and_coplanar_receivers_give_zero():
    tri = rect([-1, -1, 1.0], [2, 0, 0], [0, 2, 0])
    facing_down = np.array([[0, 0, -1.0]] * 2)
    assert point_to_triangle(ORIGIN, UP, tri, facing_down).sum() > 0
    assert point_to_triangle(ORIGIN, UP, tri, -facing_down).sum() == 0
    floor = rect([1, 1, 0], [1, 0, 0], [0, 1, 0])
    assert point_to_triangle(ORIGIN, UP, floor).sum() == 0


def test_hemisphere_closes_to_one_and_paired_matches_dense():
    big = 1e5
    ceiling = rect([-big, -big, 1.0], [2 * big, 0, 0], [0, 2 * big, 0])
    assert point_to_triangle(ORIGIN, UP, ceiling).sum() == pytest.approx(1.0, abs=1e-4)
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(50, 3))
    nrm = rng.normal(size=(50, 3))
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    tris = rng.normal(size=(50, 3, 3)) + 3
    dense = point_to_triangle(pts, nrm, tris)
    assert np.allclose(paired_point_to_triangle(pts, nrm, tris), np.diag(dense))
