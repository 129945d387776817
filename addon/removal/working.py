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


def downsample(radiance: np.ndarray, width: int, height: int) -> np.ndarray:
    """(height, width, 3) float64 area average of an (H, W, 3) panorama, negative radiance
    read as black: each output pixel is the mean over the input area it covers (fractional
    pixels weighted by their share), read in bands of rows so no float64 copy of the whole
    input is made."""
    rows_in, cols_in, channels = radiance.shape
    band = max(1, _BAND_BYTES // (cols_in * channels * 8))
    columns = np.empty((rows_in, width, channels))
    for start in range(0, rows_in, band):
        rows = np.maximum(radiance[start:start + band].astype(np.float64), 0.0)
        columns[start:start + band] = _area_average(rows, width, axis=1)
    return _area_average(columns, height, axis=0)


def upsample(image: np.ndarray, height: int, width: int) -> np.ndarray:
    """A working-resolution (h, w, C) image or (h, w) mask at (height, width): images
    bilinearly (float32, in bands of rows), masks by the nearest pixel."""
    h, w = image.shape[:2]
    y = (np.arange(height) + 0.5) * (h / height) - 0.5
    x = (np.arange(width) + 0.5) * (w / width) - 0.5
    if image.dtype == bool:
        rows = np.clip(np.round(y).astype(np.int64), 0, h - 1)
        return image[rows][:, np.mod(np.round(x).astype(np.int64), w)]
    x0 = np.floor(x).astype(np.int64)
    fx = (x - x0).astype(np.float32)[None, :, None]
    xa, xb = np.mod(x0, w), np.mod(x0 + 1, w)
    out = np.empty((height, width, image.shape[2]), dtype=np.float32)
    band = max(1, _BAND_BYTES // (width * image.shape[2] * 8))
    for start in range(0, height, band):
        yy = y[start:start + band]
        y0 = np.floor(yy).astype(np.int64)
        fy = (yy - y0).astype(np.float32)[:, None, None]
        across = image[np.clip(y0, 0, h - 1)] * (1 - fy) + image[np.clip(y0 + 1, 0, h - 1)] * fy
        out[start:start + band] = across[:, xa] * (1 - fx) + across[:, xb] * fx
    return out


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
