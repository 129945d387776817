"""Box sums, square morphology and halving on window arrays, against direct loops over the
square (the window's edge counts as outside)."""
from __future__ import annotations

import numpy as np

from addon.segmentation.masks import (
    blur,
    boundary,
    box_mean,
    box_sum,
    components,
    dilate,
    double,
    erode,
    halve,
    max_filter,
    outline,
)


def _direct_box_sum(a: np.ndarray, r: int) -> np.ndarray:
    padded = np.pad(a.astype(np.float64), [(r, r), (r, r)] + [(0, 0)] * (a.ndim - 2))
    out = np.zeros(a.shape)
    for dy in range(2 * r + 1):
        for dx in range(2 * r + 1):
            out += padded[dy:dy + a.shape[0], dx:dx + a.shape[1]]
    return out


def test_box_sum_matches_the_direct_sum_for_masks_and_colours():
    rng = np.random.default_rng(0)
    mask = rng.random((13, 17)) < 0.3
    colours = rng.random((13, 17, 3)) * np.array([1.0, 10.0, 1e4])
    for r in (0, 1, 3, 8):
        assert np.array_equal(box_sum(mask, r), _direct_box_sum(mask, r))
        np.testing.assert_allclose(box_sum(colours, r), _direct_box_sum(colours, r), rtol=1e-12)


def test_box_mean_averages_only_the_weighted_pixels():
    values = np.zeros((5, 5, 3))
    values[:, :2] = 1.0
    values[:, 2:] = 7.0
    weights = np.zeros((5, 5), dtype=bool)
    weights[:, 3:] = True
    mean, total = box_mean(values, weights, 1)
    assert np.allclose(mean[:, 2:], 7.0)
    assert np.all(mean[:, :2] == 0.0) and np.all(total[:, :2] == 0.0)
    assert total[2, 4] == 6.0


def test_max_filter_matches_the_direct_maximum_over_the_square_within_the_window():
    a = np.random.default_rng(2).random((11, 14)) - 0.5
    for r in (0, 1, 3):
        padded = np.pad(a, r, constant_values=-np.inf)
        direct = np.max([padded[dy:dy + 11, dx:dx + 14] for dy in range(2 * r + 1) for dx in range(2 * r + 1)], axis=0)
        assert np.array_equal(max_filter(a, r), direct)


def test_dilate_and_erode_are_chebyshev_and_the_edge_is_outside():
    mask = np.zeros((20, 20), dtype=bool)
    mask[5:12, 4:15] = True
    rows, cols = np.indices(mask.shape)
    ys, xs = np.nonzero(mask)
    cheb = np.min(np.maximum(np.abs(rows[..., None] - ys), np.abs(cols[..., None] - xs)), axis=-1)
    assert np.array_equal(dilate(mask, 3), cheb <= 3)
    assert np.array_equal(erode(mask, 2), np.pad(np.ones((3, 7), dtype=bool), ((7, 10), (6, 7))))
    full = np.ones((6, 6), dtype=bool)
    assert np.array_equal(erode(full, 1), np.pad(np.ones((4, 4), dtype=bool), 1))


def test_outline_and_boundary():
    mask = np.zeros((6, 7), dtype=bool)
    mask[1:5, 2:6] = True
    inner = np.zeros_like(mask)
    inner[2:4, 3:5] = True
    assert np.array_equal(outline(mask), mask & ~inner)
    ring = dilate(mask, 1) & ~mask & ~np.pad(np.ones((4, 4), dtype=bool), ((1, 1), (2, 1)))
    corners = np.zeros_like(mask)
    corners[[0, 0, 5, 5], [1, 6, 1, 6]] = True
    assert np.array_equal(boundary(mask), (mask & ~inner) | (ring & ~corners))
    # Past the window's edge is background: a mask reaching the edge has its outline there.
    full = np.ones((3, 3), dtype=bool)
    assert np.array_equal(boundary(full), outline(full)) and outline(full).sum() == 8
    assert not boundary(~full).any()


def test_halve_averages_blocks_and_double_undoes_it_for_blocky_masks():
    a = np.arange(5 * 7, dtype=np.float32).reshape(5, 7)
    h = halve(a)
    assert h.shape == (3, 4)
    assert h[0, 0] == np.mean(a[:2, :2])
    assert h[2, 3] == a[4, 6]  # the odd last row and column repeated
    blocks = np.kron(np.random.default_rng(1).random((3, 4)) < 0.5, np.ones((2, 2), dtype=bool))[:5, :7]
    assert np.array_equal(double(halve(blocks) >= 0.5, blocks.shape), blocks)


def test_blur_keeps_flat_regions_and_sums():
    flat = np.full((6, 5, 3), 2.5, dtype=np.float32)
    assert np.allclose(blur(flat), 2.5)
    spike = np.zeros((7, 7), dtype=np.float32)
    spike[3, 3] = 16.0
    assert np.isclose(blur(spike).sum(), 16.0)
    assert blur(spike)[3, 3] == 4.0 and blur(spike)[2, 2] == 1.0


def test_components_are_four_connected_and_follow_long_thin_shapes():
    mask = np.zeros((9, 12), bool)
    mask[0, :] = mask[:, 11] = True  # one long L along two edges
    mask[3:5, 1:3] = True  # a block
    mask[6, 6] = mask[7, 7] = True  # diagonal neighbours: two components
    rows, cols = np.indices(mask.shape)
    snake = (rows % 4 != 1) | ((rows % 8 == 1) & (cols == 0)) | ((rows % 8 == 5) & (cols == 9))
    for m, n in ((mask, 4), (snake[:, :10], 1)):
        got, count = components(m)
        assert count == n
        assert (got[~m] == -1).all() and set(np.unique(got[m])) == set(range(n))
    got, _ = components(mask)
    assert len(np.unique(got[0, :])) == 1 and got[0, 0] == got[8, 11]
    assert got[6, 6] != got[7, 7]
