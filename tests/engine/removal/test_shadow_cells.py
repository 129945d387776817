"""Shadows taken from the corners of cells of pixels where they agree, computed pixel by pixel
elsewhere: on a floor seen as a grid of pixels, with shadows given as functions of position."""
from __future__ import annotations

import numpy as np

from addon.removal.shadow_cells import PixelGrid, cell_shadows

H, W = 16, 24


def _floor(*, wall_from: int | None = None) -> tuple[np.ndarray, np.ndarray, PixelGrid]:
    """Points and normals of an H x W grid of pixels on the floor z = -1 (from column
    `wall_from` on a wall x = 30 instead), every pixel a receiving point."""
    r, c = np.divmod(np.arange(H * W), W)
    points = np.stack([c * 0.1 + 1.0, r * 0.1 + 1.0, np.full(H * W, -1.0)], axis=1)
    normals = np.tile([0.0, 0.0, 1.0], (H * W, 1))
    if wall_from is not None:
        wall = c >= wall_from
        points[wall] = np.stack([np.full(wall.sum(), 30.0), r[wall] * 0.1, c[wall] * 0.1], axis=1)
        normals[wall] = [-1.0, 0.0, 0.0]
    return points, normals, PixelGrid(np.arange(H * W), H, W)


def _shadow(points: np.ndarray, profile):
    """A PairShadow whose value at a point is profile(x, y) * (sender + 1), counting its pairs."""
    asked = []

    def shadow(rows: np.ndarray, senders: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        asked.append(len(rows))
        value = profile(points[rows, 0], points[rows, 1]) * (senders + 1.0)
        return np.repeat(value[:, None], 3, axis=1), np.repeat(-0.5 * value[:, None], 3, axis=1)
    return shadow, asked


def _pairs(count: int = 2) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of every pixel but those of the last cell of columns, whose corners wrap around
    to the first column (beside it in a panorama, not on this floor)."""
    pixels = np.flatnonzero(np.arange(H * W) % W < W - 4)
    return np.repeat(pixels, count), np.tile(np.arange(count), len(pixels))


def _run(points, normals, grid, profile, *, cell, budget=1.0):
    rows, senders = _pairs()
    shadow, asked = _shadow(points, profile)
    result = cell_shadows(points, normals, np.ones(len(points), dtype=bool), grid, rows, senders,
                          np.full(len(points), budget), shadow, cell=cell)
    return result, sum(asked)


def test_a_smooth_shadow_is_interpolated_from_the_corners_and_matches_the_exact_one():
    points, normals, grid = _floor()
    linear = lambda x, y: 0.2 + 0.1 * x - 0.05 * y  # noqa: E731
    exact, exact_pairs = _run(points, normals, grid, linear, cell=1)
    cells, cell_pairs = _run(points, normals, grid, linear, cell=4)
    assert cells.interpolated_points > H * W // 2
    assert cell_pairs < exact_pairs / 2
    np.testing.assert_allclose(cells.e, exact.e, atol=1e-12)
    np.testing.assert_allclose(cells.de, exact.de, atol=1e-12)


def test_a_sharp_shadow_edge_is_computed_at_its_pixels():
    points, normals, grid = _floor()
    step = lambda x, y: np.where(x + 0.3 * y < 2.05, 0.0, 1.0)  # noqa: E731
    exact, _ = _run(points, normals, grid, step, cell=1)
    cells, _ = _run(points, normals, grid, step, cell=4, budget=0.01)
    assert 0 < cells.interpolated_points < H * (W - 4)
    np.testing.assert_allclose(cells.e, exact.e, atol=1e-12)


def test_a_steep_gradient_is_interpolated_where_the_middle_pixel_confirms_it():
    points, normals, grid = _floor()
    steep = lambda x, y: 5.0 * x + 3.0 * y  # noqa: E731
    exact, exact_pairs = _run(points, normals, grid, steep, cell=1)
    cells, cell_pairs = _run(points, normals, grid, steep, cell=4, budget=1e-6)
    assert cells.interpolated_points > H * W // 2 and cell_pairs < exact_pairs / 2
    np.testing.assert_allclose(cells.e, exact.e, atol=1e-9)


def test_a_bend_inside_a_cell_is_computed_at_its_pixels():
    points, normals, grid = _floor()
    bend = lambda x, y: np.abs(x - 2.2)  # noqa: E731
    exact, _ = _run(points, normals, grid, bend, cell=1)
    cells, _ = _run(points, normals, grid, bend, cell=4, budget=1e-6)
    np.testing.assert_allclose(cells.e, exact.e, atol=1e-9)


def test_corners_that_disagree_by_less_than_the_budget_are_interpolated():
    points, normals, grid = _floor()
    step = lambda x, y: np.where(x < 2.05, 0.0, 0.001)  # noqa: E731
    loose, _ = _run(points, normals, grid, step, cell=4, budget=1.0)
    strict, _ = _run(points, normals, grid, step, cell=4, budget=1e-6)
    assert loose.interpolated_points > strict.interpolated_points


def test_a_pixel_takes_only_the_corners_on_its_own_surface():
    points, normals, grid = _floor(wall_from=10)
    # Even on each surface, a step between them within the budget: the cells across the edge
    # (columns 8-12) are smooth, and each side mixes its own corners.
    per_surface = lambda x, y: np.where(x > 20.0, 1.5, 1.0)  # noqa: E731
    exact, _ = _run(points, normals, grid, per_surface, cell=1)
    cells, _ = _run(points, normals, grid, per_surface, cell=4, budget=2.0)
    np.testing.assert_allclose(cells.e, exact.e, atol=1e-12)
    assert cells.interpolated_points == H * (W - 4)


def test_a_shadow_that_differs_across_a_surface_edge_is_computed_there():
    points, normals, grid = _floor(wall_from=10)
    per_surface = lambda x, y: np.where(x > 20.0, 1.5, 1.0)  # noqa: E731
    exact, _ = _run(points, normals, grid, per_surface, cell=1)
    cells, _ = _run(points, normals, grid, per_surface, cell=4, budget=0.1)
    np.testing.assert_allclose(cells.e, exact.e, atol=1e-12)
    assert cells.interpolated_points <= H * (W - 4) - H * 4


def test_the_last_row_of_cells_closes_on_the_panoramas_last_row():
    points, normals, grid = _floor()
    steep = lambda x, y: 5.0 * x + 3.0 * y  # noqa: E731
    exact, _ = _run(points, normals, grid, steep, cell=1)
    # Cells of 6 end in one of rows 12-15 (a span of 3), whose pixels are mixed as well; cells
    # of 5 in one of row 15 alone, which has no corners below it. (Columns 18-19 of the cells
    # of 6 take corners wrapped around to column 0, where the gradient is another.)
    for cell, mixed in ((6, H * 18), (5, (H - 1) * 20)):
        cells, _ = _run(points, normals, grid, steep, cell=cell, budget=1e-6)
        np.testing.assert_allclose(cells.e, exact.e, atol=1e-9)
        assert cells.interpolated_points == mixed


def test_without_a_grid_every_pair_is_computed():
    points, normals, _ = _floor()
    linear = lambda x, y: x  # noqa: E731
    rows, senders = _pairs()
    shadow, asked = _shadow(points, linear)
    result = cell_shadows(points, normals, np.ones(len(points), dtype=bool), None, rows, senders,
                          np.ones(len(points)), shadow, cell=4)
    assert result.interpolated_points == 0 and sum(asked) == len(rows) == result.computed_pairs


def test_unusable_corners_leave_their_cells_computed():
    points, normals, grid = _floor()
    usable = np.ones(len(points), dtype=bool)
    usable[::2] = False
    rows, senders = _pairs()
    shadow, _ = _shadow(points, lambda x, y: x)
    result = cell_shadows(points, normals, usable, grid, rows, senders, np.ones(len(points)), shadow, cell=4)
    assert result.interpolated_points == 0
