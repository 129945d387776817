"""The panorama read in bands: the bands cover every row once, the clamp reads negative radiance
as black, and the counts over the whole panorama match a whole-array count without building
full-size temporaries."""
from __future__ import annotations

import itertools
import tracemalloc

import numpy as np
import pytest

from addon import radiance


@pytest.mark.parametrize("height, width", [(1, 1), (7, 3), (64, 1 << 16), (3, 1 << 23)])
def test_bands_cover_every_row_once_in_order(height, width):
    bands = list(radiance.row_bands(height, width))
    assert bands[0][0] == 0 and bands[-1][1] == height
    assert all(stop > start for start, stop in bands)
    assert all(a[1] == b[0] for a, b in itertools.pairwise(bands))


def test_clamped_rows_read_negative_radiance_as_black_in_a_new_array():
    hdri = np.array([[[-1.0, 2.0, 0.5]], [[3.0, -0.0, -4.0]], [[1.0, 1.0, 1.0]]], np.float32)
    rows = radiance.clamped_rows(hdri, 0, 2)
    assert rows.dtype == np.float32
    np.testing.assert_array_equal(rows, [[[0.0, 2.0, 0.5]], [[3.0, 0.0, 0.0]]])
    assert hdri[0, 0, 0] == -1.0


def _broken(height: int = 300, width: int = 600) -> np.ndarray:
    hdri = np.random.default_rng(5).random((height, width, 3)).astype(np.float32)
    hdri[0, 0] = [-1.0, -2.0, 0.5]  # one pixel, two channels
    hdri[150, 7, 2] = -0.1
    hdri[299, 599, 0] = np.nan
    hdri[42, 1, 1] = np.inf
    hdri[42, 2] = -np.inf  # infinite and negative
    return hdri


def test_counts_are_of_pixels_over_all_bands(monkeypatch):
    monkeypatch.setattr(radiance, "_BAND_PIXELS", 6000)  # ten rows a band
    hdri = _broken()
    assert radiance.negative_pixels(hdri) == int((hdri < 0).any(axis=2).sum()) == 3
    assert radiance.non_finite_pixels(hdri) == int((~np.isfinite(hdri)).any(axis=2).sum()) == 3


def test_counting_builds_no_full_size_temporary(monkeypatch):
    monkeypatch.setattr(radiance, "_BAND_PIXELS", 6000)
    hdri = _broken()
    tracemalloc.start()
    try:
        radiance.negative_pixels(hdri)
        radiance.non_finite_pixels(hdri)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    # A whole-array test would allocate a bool per value (hdri.size bytes).
    assert peak < hdri.size // 4


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_all_finite_finds_one_non_finite_value_anywhere(bad):
    values = np.random.default_rng(2).normal(size=(20, 30, 3)).astype(np.float32) * 1e30
    assert radiance.all_finite(values)
    values[19, 29, 2] = bad
    assert not radiance.all_finite(values)


def test_the_difference_is_rounded_to_its_stored_precision_in_place():
    from addon.radiance import STORED_MANTISSA_BITS, round_to_stored_precision

    rng = np.random.default_rng(3)
    values = (rng.standard_normal((64, 32, 3)) * 10.0 ** rng.uniform(-30, 30, (64, 32, 3))).astype(np.float32)
    rounded = values.copy()
    assert round_to_stored_precision(rounded) is rounded
    relative = np.abs(rounded.astype(np.float64) / values - 1)
    assert relative.max() <= 2.0 ** -(STORED_MANTISSA_BITS + 1)
    assert np.all(rounded.view(np.uint32) & np.uint32((1 << (23 - STORED_MANTISSA_BITS)) - 1) == 0)
    assert np.array_equal(round_to_stored_precision(rounded.copy()), rounded)  # already stored: unchanged
    special = np.array([np.inf, -np.inf, np.nan, 0.0, 0.25, -1.5], np.float32)
    out = round_to_stored_precision(special.copy())
    assert np.isposinf(out[0]) and np.isneginf(out[1]) and np.isnan(out[2])
    assert out[3:].tolist() == [0.0, 0.25, -1.5]
