"""The translations under which a plane's visible texture repeats: tile and plank periods.

On a rectified floor, tiles, planks and parquet repeat by translation. The visible texture's
self-difference D(t), the mean squared difference between the known pixels x and x + t where
both are known, is low at those translations and high at others (patch-offset statistics, He
and Sun 2012, taken over the whole visible floor at once). D is computed for every shift by
FFT on a block-averaged copy, its clearest local minima are kept, and each is refined to the
cell on the raster itself around the hole, where it will be used.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..segmentation.masks import box_mean
from .correlation import correlation, correlation_size, cross_spectrum, spectrum

_COARSE_SIDE = 160  # the FFT runs on a copy at most this many blocks across: a few ms
_MIN_OVERLAP = 0.2  # a shift counts where this share of the known pixels stays known under it
# A translation is dominant where the texture differs from itself by at most this share of its
# difference under a typical shift: tiles and plank joints reach 0.1-0.5, carpet and concrete
# (whose self-difference is flat past the grain) stay near 1.
DOMINANT = 0.6
_SUPPRESS = 2  # coarse blocks: minima closer than this to a better one are the same translation
_SAMPLES = 2048  # ring pixels the refinement compares: enough for a mean, cheap for 700 trials


@dataclass(frozen=True)
class Translations:
    """(K, 2) shifts (rows, columns) in raster cells, best first, and each one's self-difference
    D(t) relative to the median over all shifts (0 = a perfect repeat, 1 = a typical shift)."""

    shifts: np.ndarray
    contrast: np.ndarray

    @property
    def dominant(self) -> bool:
        """Whether the texture repeats at all: a stochastic texture (carpet, concrete) has no
        shift that matches it much better than any other."""
        return bool(len(self.shifts)) and float(self.contrast[0]) <= DOMINANT

    @property
    def tiling(self) -> bool:
        """Whether the dominant translations span the plane (two of them at least 15 degrees
        apart): a grid of tiles. Wood grain and rows of planks repeat along one direction only."""
        t = self.shifts[self.contrast <= DOMINANT].astype(np.float64)
        if len(t) < 2:
            return False
        cross = np.abs(t[:, None, 0] * t[None, :, 1] - t[:, None, 1] * t[None, :, 0])
        return bool((cross > np.sin(np.radians(15)) * np.outer(*(2 * [np.hypot(*t.T)]))).any())


def dominant_translations(image: np.ndarray, known: np.ndarray, hole: np.ndarray, *, count: int = 16,
                          min_shift: int = 6) -> Translations:
    """The `count` translations of the `known` pixels of `image` (H, W, C) with the lowest
    self-difference, at least `min_shift` cells long (shorter ones only say that the texture is
    smooth at the cell's scale), refined around the `hole`. Symmetric
    shifts t and -t are both kept: the hole takes its copies from either side."""
    luma = image.mean(axis=2)
    block = max(1, int(np.ceil(max(image.shape[:2]) / _COARSE_SIDE)))
    values, weight = _block_mean(luma, known, block)
    full = weight >= 0.999
    # Edges, not shades: planks of random shades still repeat their joints, and the lamp's
    # falloff left in the reflectance would make every short shift look alike.
    values = values - box_mean(values[..., None], full, 2)[0][..., 0]
    d, overlap = _self_difference(values, full)
    ty = np.arange(-(values.shape[0] - 1), values.shape[0])
    tx = np.arange(-(values.shape[1] - 1), values.shape[1])
    ok = overlap >= _MIN_OVERLAP * full.sum()
    typical = float(np.median(d[ok])) if ok.any() else 0.0
    if typical <= 0.0:
        return Translations(np.zeros((0, 2), np.int64), np.zeros(0))
    far = np.hypot(*np.meshgrid(ty, tx, indexing="ij")) * block >= min_shift
    score = np.where(ok & far & _local_minima(d), d / typical, np.inf)
    picked = []
    for _ in range(count):
        best = int(np.argmin(score))
        if not np.isfinite(score.flat[best]) or score.flat[best] > 1.0:
            break
        by, bx = np.unravel_index(best, score.shape)
        picked.append((ty[by] * block, tx[bx] * block))
        score[max(by - _SUPPRESS, 0):by + _SUPPRESS + 1, max(bx - _SUPPRESS, 0):bx + _SUPPRESS + 1] = np.inf
    if not picked:
        return Translations(np.zeros((0, 2), np.int64), np.zeros(0))
    shifts, diff = _refine(np.array(picked, np.int64), luma, known, hole, block)
    order = np.argsort(diff, kind="stable")
    return Translations(shifts[order], diff[order] / max(_typical_difference(luma, known, hole), 1e-30))


def relative_difference(image: np.ndarray, known: np.ndarray, hole: np.ndarray, shifts: np.ndarray, *,
                        ring: int = 8) -> np.ndarray:
    """(K,) how well the known pixels within `ring` of the `hole`'s bounding box match themselves
    under each shift, relative to an arbitrary shift (as `Translations.contrast`; inf where too
    few pairs)."""
    luma = image.mean(axis=2)
    ys, xs = _ring(hole, known, ring)
    diff = _pair_difference(luma, known, ys, xs, np.asarray(shifts, np.int64).reshape(-1, 2))
    return diff / max(_typical_difference(luma, known, hole), 1e-30)


def _block_mean(values: np.ndarray, known: np.ndarray, block: int) -> tuple[np.ndarray, np.ndarray]:
    """Means of `values` over the known pixels of each block x block square, and the known share."""
    h, w = values.shape
    hb, wb = -(-h // block), -(-w // block)
    pad = ((0, hb * block - h), (0, wb * block - w))
    k = np.pad(known.astype(np.float64), pad).reshape(hb, block, wb, block).sum(axis=(1, 3))
    v = np.pad(np.where(known, values, 0.0), pad).reshape(hb, block, wb, block).sum(axis=(1, 3))
    return v / np.maximum(k, 1), k / block**2


def _self_difference(values: np.ndarray, valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """D(t) for every shift t of an (h, w) image, indexed from -(h-1), -(w-1); and how many
    pixel pairs each mean is over."""
    h, w = values.shape
    size = correlation_size((h, w), (h, w))
    v = np.where(valid, values, 0.0)
    f_valid, f_values = spectrum(valid.astype(np.float64), size), spectrum(v, size)
    shifts = np.ix_(np.arange(-(h - 1), h) % size[0], np.arange(-(w - 1), w) % size[1])
    count = np.rint(correlation(cross_spectrum(f_valid, f_valid), size))[shifts]
    # sum over pairs of a(x)^2 + a(x+t)^2 - 2 a(x) a(x+t)
    f_squares = spectrum(v * v, size)
    num = correlation(cross_spectrum(f_squares, f_valid) + cross_spectrum(f_valid, f_squares)
                      - 2 * cross_spectrum(f_values, f_values), size)[shifts]
    return np.maximum(num, 0.0) / np.maximum(count, 1), count


def _local_minima(d: np.ndarray) -> np.ndarray:
    """Where d is no larger than any of its 8 neighbours."""
    p = np.pad(d, 1, constant_values=np.inf)
    h, w = d.shape
    return np.all([d <= p[1 + dy:1 + dy + h, 1 + dx:1 + dx + w]
                   for dy in (-1, 0, 1) for dx in (-1, 0, 1) if dy or dx], axis=0)


def _ring(hole: np.ndarray, known: np.ndarray, radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Up to _SAMPLES of the known pixels within `radius` of the hole's bounding box, evenly
    spread, as (rows, columns)."""
    near = np.zeros(hole.shape, bool)
    ys, xs = np.nonzero(hole)
    y0, y1 = max(ys.min() - radius, 0), min(ys.max() + radius + 1, hole.shape[0])
    x0, x1 = max(xs.min() - radius, 0), min(xs.max() + radius + 1, hole.shape[1])
    near[y0:y1, x0:x1] = True
    ys, xs = np.nonzero(near & known)
    step = max(1, len(ys) // _SAMPLES)
    return ys[::step], xs[::step]


def _pair_difference(luma: np.ndarray, known: np.ndarray, ys: np.ndarray, xs: np.ndarray,
                     shifts: np.ndarray) -> np.ndarray:
    """(K,) mean squared difference of pixels (ys, xs) and the same moved by each shift, over
    the pairs known at both ends (inf where too few)."""
    h, w = luma.shape
    sy, sx = ys[None] + shifts[:, :1], xs[None] + shifts[:, 1:]
    inside = (sy >= 0) & (sy < h) & (sx >= 0) & (sx < w)
    sy, sx = np.clip(sy, 0, h - 1), np.clip(sx, 0, w - 1)
    ok = inside & known[sy, sx]
    diff = np.where(ok, (luma[sy, sx] - luma[ys, xs][None]) ** 2, 0.0).sum(axis=1)
    n = ok.sum(axis=1)
    return np.where(n >= _MIN_OVERLAP * len(ys), diff / np.maximum(n, 1), np.inf)


def _refine(shifts: np.ndarray, luma: np.ndarray, known: np.ndarray, hole: np.ndarray, block: int
            ) -> tuple[np.ndarray, np.ndarray]:
    """Each coarse shift moved to the cell, within a block, that best matches the known ring
    around the hole with itself; and that best mean squared difference."""
    ys, xs = _ring(hole, known, max(8, block))
    steps = np.arange(-block + 1, block) if block > 1 else np.zeros(1, np.int64)
    grid = np.stack(np.meshgrid(steps, steps, indexing="ij"), axis=-1).reshape(-1, 2)
    trial = (shifts[:, None, :] + grid[None]).reshape(-1, 2)
    diff = _pair_difference(luma, known, ys, xs, trial).reshape(len(shifts), len(grid))
    best = diff.argmin(axis=1)
    return shifts + grid[best], diff[np.arange(len(shifts)), best]


def _typical_difference(luma: np.ndarray, known: np.ndarray, hole: np.ndarray) -> float:
    """The ring's mean squared difference with itself under shifts of a few cells to a tenth of
    the raster in every direction: what an arbitrary shift gives."""
    ys, xs = _ring(hole, known, 8)
    span = max(4, max(luma.shape) // 10)
    a = np.linspace(0.0, 2 * np.pi, 16, endpoint=False)
    shifts = np.rint(np.stack([np.sin(a), np.cos(a)], axis=1)[:, None, :]
                     * np.array([span / 3, span])[None, :, None]).reshape(-1, 2).astype(np.int64)
    diff = _pair_difference(luma, known, ys, xs, shifts)
    return float(np.median(diff[np.isfinite(diff)])) if np.isfinite(diff).any() else 0.0
