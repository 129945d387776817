"""Sampling the refined pixels on every other pixel, from arrays."""
from __future__ import annotations

import numpy as np

from addon.removal.refine_samples import refine_samples, sample_stride

W, H = 40, 20


def _surface(keys: np.ndarray):
    return lambda rows, cols: keys[rows, cols]


def _mix(samples, values: np.ndarray) -> np.ndarray:
    return np.einsum("nk,nk->n", samples.weight, values.ravel()[samples.computed][samples.corner])


def test_pixels_on_one_surface_is_sampled_on_even_pixels_and_mixed_exactly_where_light_is_linear():
    keys = np.zeros((H, W), dtype=np.int64)
    keys[8:12, 10:20] = -1  # the object
    rows, cols = np.nonzero(np.zeros((H, W), dtype=bool) | (np.abs(np.arange(H)[:, None] - 9.5) < 4.5)
                            & (np.abs(np.arange(W)[None, :] - 14.5) < 7.5) & (keys >= 0))
    pixel = rows * W + cols
    samples = refine_samples(pixel, W, H, _surface(keys), stride=2)
    r, c = np.divmod(samples.computed, W)
    assert np.all((r % 2 == 0) & (c % 2 == 0))
    assert len(samples.computed) < 0.5 * len(pixel)
    assert np.allclose(samples.weight.sum(axis=1), 1.0)
    linear = 0.3 * np.arange(H)[:, None] + 0.1 * np.arange(W)[None, :] + 2.0
    # Where all corners are on the surface the bilinear mix of a linear field is exact.
    full = (samples.weight > 0).sum(axis=1) == np.where(rows % 2, 2, 1) * np.where(cols % 2, 2, 1)
    assert full.sum() > 0.5 * len(pixel)
    assert np.allclose(_mix(samples, linear)[full], linear.ravel()[pixel][full])
    # Every other pixel still takes values from at most a pixel away.
    assert np.abs(_mix(samples, linear) - linear.ravel()[pixel]).max() <= 0.3 + 0.1 + 1e-9


def test_samples_on_another_surface_are_never_mixed_and_a_pixel_without_any_is_its_own():
    keys = np.zeros((H, W), dtype=np.int64)
    keys[:, 7] = 1  # a wall one column wide: its odd-column pixels have no even sample on it
    pixel = np.array([5 * W + 6, 5 * W + 7, 6 * W + 7, 5 * W + 8])
    samples = refine_samples(pixel, W, H, _surface(keys), stride=2)
    r, c = np.divmod(samples.computed[samples.corner], W)
    used = samples.weight > 0
    assert np.all(keys[r[used], c[used]] == keys.ravel()[pixel][np.nonzero(used)[0]])
    assert 5 * W + 7 in samples.computed and 6 * W + 7 in samples.computed


def test_the_samples_wrap_round_the_seam_and_stops_at_the_last_row():
    keys = np.zeros((H, W), dtype=np.int64)
    pixel = np.array([3 * W + W - 1, (H - 1) * W + 5])
    samples = refine_samples(pixel, W, H, _surface(keys), stride=2)
    r, c = np.divmod(samples.computed[samples.corner[0]][samples.weight[0] > 0], W)
    assert set(c.tolist()) == {W - 2, 0} and set(r.tolist()) == {2, 4}
    r, c = np.divmod(samples.computed[samples.corner[1]][samples.weight[1] > 0], W)
    assert set(r.tolist()) == {H - 2} and set(c.tolist()) == {4, 6}


def test_the_stride_is_half_the_working_pixel_rounded_down_to_a_power_of_two():
    assert [sample_stride(f) for f in (1, 2, 3, 4, 6, 8, 12, 16)] == [1, 1, 1, 2, 2, 4, 4, 8]


def test_a_wider_stride_mixes_the_cell_corners_bilinearly():
    keys = np.zeros((H, W), dtype=np.int64)
    pixel = np.array([5 * W + 6, 4 * W + 4])
    samples = refine_samples(pixel, W, H, _surface(keys), stride=4)
    r, c = np.divmod(samples.computed[samples.corner[0]], W)
    assert set(zip(r.tolist(), c.tolist(), strict=True)) == {(4, 4), (4, 8), (8, 4), (8, 8)}
    np.testing.assert_allclose(samples.weight[0], [0.75 * 0.5, 0.75 * 0.5, 0.25 * 0.5, 0.25 * 0.5])
    linear = 0.3 * np.arange(H)[:, None] + 0.1 * np.arange(W)[None, :]
    np.testing.assert_allclose(_mix(samples, linear), linear.ravel()[pixel])
    assert samples.weight[1].tolist() == [1.0, 0.0, 0.0, 0.0]
