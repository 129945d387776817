"""Box filters, square morphology and halving on a window's (h, w) arrays; what lies past the
window's edge counts as outside every mask (the caller's window edges are background)."""
from __future__ import annotations

import numpy as np


def box_sum(a: np.ndarray, radius: int) -> np.ndarray:
    """Sums of `a` ((h, w) or (h, w, c)) over the (2 radius + 1)^2 square around each pixel,
    zero past the edges; float64 for float input, int64 for bool or int."""
    return rect_sum(a, radius, radius)


def rect_sum(a: np.ndarray, rows: int, cols: int) -> np.ndarray:
    """Sums of `a` ((h, w) or (h, w, c)) over the (2 rows + 1) x (2 cols + 1) rectangle around
    each pixel, zero past the edges; float64 for float input, int64 for bool or int."""
    dtype = np.float64 if np.issubdtype(a.dtype, np.floating) else np.int64
    out = np.asarray(a, dtype=dtype)
    for axis, radius in ((0, rows), (1, cols)):
        if radius <= 0:
            out = out.copy()
            continue
        m = np.moveaxis(out, axis, 0)
        n = len(m)
        zeros = np.zeros((radius + 1, *m.shape[1:]), dtype=dtype)
        # Running sums stay exact in float64 even next to a lamp 1e4 times the floor.
        c = np.cumsum(np.concatenate([zeros, m, zeros[:radius]]), axis=0)
        out = np.moveaxis(c[2 * radius + 1:] - c[:n], 0, axis)
    return out


def box_mean(values: np.ndarray, weights: np.ndarray, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Mean of `values` ((h, w, c)) over the pixels where `weights` ((h, w), bool or float) is set,
    within the square of `radius` around each pixel, and that square's total weight ((h, w));
    the mean is 0 where the weight is."""
    w = np.asarray(weights, dtype=np.float64)
    total = box_sum(w, radius)
    summed = box_sum(values * w[..., None], radius)
    mean = summed / np.maximum(total, 1e-12)[..., None]
    return mean, total


def dilate(mask: np.ndarray, radius: int) -> np.ndarray:
    """Pixels within `radius` (Chebyshev) of a pixel of `mask`."""
    return box_sum(mask, radius) > 0


def max_filter(a: np.ndarray, radius: int) -> np.ndarray:
    """The largest value of `a` ((h, w)) within the square of `radius` around each pixel, as
    float64; past the edges nothing is counted."""
    out = np.asarray(a, dtype=np.float64)
    for axis in (0, 1):
        m = np.moveaxis(out, axis, 0)
        edge = np.full((radius, *m.shape[1:]), -np.inf)
        windows = np.lib.stride_tricks.sliding_window_view(np.concatenate([edge, m, edge]), 2 * radius + 1, axis=0)
        out = np.moveaxis(windows.max(axis=-1), 0, axis)
    return out


def erode(mask: np.ndarray, radius: int) -> np.ndarray:
    """Pixels of `mask` whose whole square of `radius` lies in it (and in the window)."""
    return box_sum(mask, radius) == (2 * radius + 1) ** 2


def outline(mask: np.ndarray, *, outside: bool = False) -> np.ndarray:
    """Pixels of `mask` with a 4-neighbour not in it; past the window's edge is `outside`."""
    m = np.asarray(mask, dtype=bool)
    p = np.pad(m, 1, constant_values=outside)
    inner = p[:-2, 1:-1] & p[2:, 1:-1] & p[1:-1, :-2] & p[1:-1, 2:]
    return m & ~inner


def boundary(mask: np.ndarray) -> np.ndarray:
    """Pixels on either side of the outline of `mask`: those with a 4-neighbour of the other label."""
    return outline(mask) | outline(~np.asarray(mask, dtype=bool), outside=True)


def halve(a: np.ndarray) -> np.ndarray:
    """(ceil(h / 2), ceil(w / 2), ...) means of 2 x 2 blocks of `a` ((h, w) or (h, w, c)), the
    last row and column repeated where h or w is odd; float32."""
    a = np.asarray(a, dtype=np.float32)
    a = np.pad(a, [(0, a.shape[0] % 2), (0, a.shape[1] % 2)] + [(0, 0)] * (a.ndim - 2), mode="edge")
    return 0.25 * (a[0::2, 0::2] + a[1::2, 0::2] + a[0::2, 1::2] + a[1::2, 1::2])


def double(mask: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    """`mask` ((h, w)) repeated into 2 x 2 blocks, cut to `shape` (h, w) (the inverse of halve)."""
    return np.repeat(np.repeat(mask, 2, axis=0), 2, axis=1)[:shape[0], :shape[1]]


def blur(a: np.ndarray) -> np.ndarray:
    """`a` ((h, w) or (h, w, c)) smoothed by the 3x3 binomial kernel, edges repeated."""
    out = np.asarray(a, dtype=np.float32)
    for axis in (0, 1):
        m = np.moveaxis(out, axis, 0)
        p = np.concatenate([m[:1], m, m[-1:]])
        out = np.moveaxis(0.25 * p[:-2] + 0.5 * p[1:-1] + 0.25 * p[2:], 0, axis)
    return np.ascontiguousarray(out)


def components(mask: np.ndarray) -> tuple[np.ndarray, int]:
    """(h, w) the 4-connected component (0..n-1) of each pixel of `mask` (-1 elsewhere), and n.
    Each pixel takes its neighbours' smallest index until none changes, jumping along the chain
    of indices it points to, so that a long thin component needs few rounds."""
    m = np.asarray(mask, dtype=bool)
    h, w = m.shape
    none = h * w
    index = np.where(m, np.arange(none).reshape(h, w), none)
    while True:
        p = np.pad(index, 1, constant_values=none)
        least = np.where(m, np.minimum.reduce([index, p[:-2, 1:-1], p[2:, 1:-1], p[1:-1, :-2], p[1:-1, 2:]]), none)
        flat = least.ravel()
        linked = flat < none
        flat[linked] = np.minimum(flat[linked], flat[flat[linked]])
        if np.array_equal(least, index):
            break
        index = least
    out = np.full((h, w), -1, dtype=np.int64)
    roots, out[m] = np.unique(index[m], return_inverse=True)
    return out, len(roots)
