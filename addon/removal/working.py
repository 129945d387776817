"""The working resolution: the light is solved on a smaller copy of the panorama, since the
change of light is smooth except where the full-resolution stage refines it."""
from __future__ import annotations

import numpy as np

_BAND_BYTES = 64 << 20  # rows of the full panorama averaged at a time (float64)


def working_size(width: int, height: int, *, max_width: int) -> tuple[int, int]:
    """(width, height) the light is solved at: the panorama's own up to `max_width`."""
    if width <= max_width:
        return width, height
    return max_width, max_width // 2


def downsample(image: np.ndarray, width: int, height: int) -> np.ndarray:
    """(height, width, C) float64 area average of an (H, W, C) image: each output pixel is the
    mean over the input area it covers (fractional pixels weighted by their share), read in
    bands of rows so no float64 copy of the whole input is made."""
    rows_in, cols_in, channels = image.shape
    band = max(1, _BAND_BYTES // (cols_in * channels * 8))
    columns = np.empty((rows_in, width, channels))
    for start in range(0, rows_in, band):
        columns[start:start + band] = _area_average(image[start:start + band].astype(np.float64), width, axis=1)
    return _area_average(columns, height, axis=0)


def _area_average(values: np.ndarray, size: int, *, axis: int) -> np.ndarray:
    """`values` averaged over `size` equal bins along `axis`, from its running sum read at the
    (fractional) bin edges."""
    n = values.shape[axis]
    moved = np.moveaxis(values, axis, 0)
    running = np.concatenate([np.zeros((1, *moved.shape[1:])), np.cumsum(moved, axis=0)])
    edges = np.arange(size + 1) * (n / size)
    whole = np.minimum(np.floor(edges).astype(np.int64), n - 1)
    part = (edges - whole)[(...,) + (None,) * (moved.ndim - 1)]
    at_edges = running[whole] + part * moved[whole]
    return np.moveaxis((at_edges[1:] - at_edges[:-1]) / (n / size), 0, axis)
