"""Lat-long images at another size: area averages where an axis shrinks, linear interpolation
where it grows (wrapping round the u seam, clamped at the poles)."""
from __future__ import annotations

import numpy as np


def resample_axis(values: np.ndarray, size: int, *, axis: int) -> np.ndarray:
    """`values` at `size` samples along `axis` (0: rows, 1: columns), in their own dtype.

    Shrinking, each sample is the mean over the input it covers, fractional pixels weighted by
    their share (so the total is kept); growing, it is interpolated between the two input
    pixels around its centre."""
    n = values.shape[axis]
    if size == n:
        return values
    if size < n:
        return _area_average(values, size, axis=axis).astype(values.dtype, copy=False)
    return interpolate(values, size, axis=axis)


def interpolate(values: np.ndarray, size: int, *, axis: int, samples: np.ndarray | None = None) -> np.ndarray:
    """`values` linearly interpolated to `size` samples along `axis`, or only to the samples
    with the indices `samples` (a band of a large output)."""
    n = values.shape[axis]
    index = np.arange(size) if samples is None else np.asarray(samples)
    x = (index + 0.5) * n / size - 0.5
    x0 = np.floor(x).astype(np.int64)
    weight = (x - x0).astype(values.dtype if values.dtype.kind == "f" else np.float64)
    if axis == 1:
        low, high = np.mod(x0, n), np.mod(x0 + 1, n)
    else:
        low, high = np.clip(x0, 0, n - 1), np.clip(x0 + 1, 0, n - 1)
    shape = [1] * values.ndim
    shape[axis] = len(index)
    weight = weight.reshape(shape)
    return np.take(values, low, axis=axis) * (1 - weight) + np.take(values, high, axis=axis) * weight


def _area_average(values: np.ndarray, size: int, *, axis: int) -> np.ndarray:
    """`values` averaged over `size` equal bins along `axis` (float64): whole blocks by their
    mean, fractional bins from the running sum read at their edges."""
    n = values.shape[axis]
    moved = np.moveaxis(values, axis, 0)
    if n % size == 0:
        out = moved.reshape(size, n // size, *moved.shape[1:]).mean(axis=1, dtype=np.float64)
        return np.moveaxis(out, 0, axis)
    running = np.concatenate([np.zeros((1, *moved.shape[1:])), np.cumsum(moved, axis=0, dtype=np.float64)])
    edges = np.arange(size + 1) * (n / size)
    whole = np.minimum(np.floor(edges).astype(np.int64), n - 1)
    part = (edges - whole)[(...,) + (None,) * (moved.ndim - 1)]
    at_edges = running[whole] + part * moved[whole]
    return np.moveaxis((at_edges[1:] - at_edges[:-1]) / (n / size), 0, axis)
