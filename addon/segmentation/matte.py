"""The object's share of each pixel along its outline (a matte), from the binary labelling.

A pixel the outline crosses mixes the object's colour f and the background's b in linear
radiance, c = alpha f + (1 - alpha) b; alpha is the projection of c - b onto f - b, with f and b
the median colours of nearby pixels that lie clearly on either side (a median, since one lamp
pixel beside the outline would drag a mean by orders of magnitude). c is the pixel's colour
smoothed by the 3x3 binomial kernel: Monte Carlo noise of 10-30 % would otherwise flip pixels,
and a symmetric kernel leaves the 0.5 contour of a straight edge where it is. That contour
follows the edge to a fraction of a pixel, which the binary labelling cannot.
"""
from __future__ import annotations

import numpy as np

from .masks import blur, dilate

_TELLING = 4.0  # how many times the pixels' noise the two sides must differ by for a matte


def soft_alpha(image: np.ndarray, labels: np.ndarray, decided: np.ndarray, *, strip: int = 2,
               reach: int = 4) -> np.ndarray:
    """(h, w) float32 alpha in [0, 1] for a window (h, w, 3) of linear radiance and its labels
    (h, w) bool: 1 / 0 except on `decided` (h, w) bool pixels within `strip` px (Chebyshev) of
    the other label, where it is the mixing share, f and b taken within `reach` px."""
    rgb = np.asarray(image, dtype=np.float32)
    near = dilate(labels, strip) & dilate(~labels, strip)
    alpha = labels.astype(np.float32)
    ys, xs = np.nonzero(near & decided)
    if not len(ys):
        return alpha
    d = np.arange(-reach, reach + 1)
    # (n, k) neighbours of each pixel to mix, clamped into the window (a clamped duplicate only
    # repeats a pixel that is already among them).
    ny = np.clip(ys[:, None] + np.repeat(d, len(d))[None], 0, rgb.shape[0] - 1)
    nx = np.clip(xs[:, None] + np.tile(d, len(d))[None], 0, rgb.shape[1] - 1)
    colours = rgb[ny, nx]
    side = labels[ny, nx]
    clear = ~near[ny, nx]
    f, f_spread = _robust_colour(colours, side, clear)
    b, b_spread = _robust_colour(colours, ~side, clear)
    both = np.isfinite(f).all(-1) & np.isfinite(b).all(-1)
    ys, xs, f, b = ys[both], xs[both], f[both], b[both]
    noise2 = 0.5 * (f_spread[both] ** 2 + b_spread[both] ** 2)
    c = blur(rgb)[ys, xs]
    diff = f - b
    d2 = (diff * diff).sum(-1)
    share = np.clip(((c - b) * diff).sum(-1) / np.maximum(d2, 1e-30), 0.0, 1.0)
    residual = c - b - share[:, None] * diff
    # The labelling stands where the sides differ by under _TELLING times the pixels' noise (the
    # share would be noise: its spread is about 0.4 noise / |f - b| after the smoothing) and
    # where the colour is no mix of the two (a lamp's glow beside the outline).
    telling = (d2 > _TELLING ** 2 * noise2) & (d2 > 0.0) & ((residual ** 2).sum(-1) <= d2)
    alpha[ys, xs] = np.where(telling, share, alpha[ys, xs])
    return alpha


def _robust_colour(colours: np.ndarray, side: np.ndarray, clear: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) per-channel median of colours (n, k, 3) over the `side` (n, k) neighbours that are
    `clear` of the outline (over all of the side where none is: a leg a pixel or two wide),
    inf where the side is absent; and (n,) their spread, the interquartile range over 1.349 (the
    standard deviation of a normal distribution), root mean square over the channels."""
    use = side & (clear | ~(side & clear).any(axis=1, keepdims=True))
    count = use.sum(axis=1)
    ranked = np.sort(np.where(use[..., None], colours, np.inf), axis=1)
    rows = np.arange(len(colours))
    last = np.maximum(count - 1, 0)
    lo, hi = ranked[rows, last // 2], ranked[rows, count // 2]
    spread = (ranked[rows, (3 * last) // 4] - ranked[rows, last // 4]) / 1.349
    present = (count > 0)[:, None]
    return (np.where(present, 0.5 * (lo + hi), np.inf),
            np.where(present[:, 0], np.sqrt(np.mean(np.where(present, spread, 0.0) ** 2, axis=-1)), 0.0))
