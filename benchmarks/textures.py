"""Procedural floor textures for the synthesis benchmark: seeded, numpy only, RGB float32 in 0..1.

tiles: 64 px tiles with 3 px grout and mottled, slightly varying tile colours; planks: wood planks
48 px wide with grain and staggered joints; herringbone: 16 x 64 px wood blocks in a herringbone,
each its own shade; hexagons: hexagonal tiles 56 px across with grout; carpet: fine isotropic
pile with faint tufts; concrete: blotchy low-frequency shading, fine grain and pores; noise:
stochastic gravel-like multi-scale noise; gradient: a smooth diagonal gradient with faint noise.

`lighting` gives the irradiance on such a floor before and after an object is removed from it: a
lamp's falloff, and the object's soft shadow, which the removal takes away.
"""
from __future__ import annotations

import numpy as np


def smooth_noise(rng: np.random.Generator, shape: tuple[int, int], sigma: float) -> np.ndarray:
    """White noise low-passed by a Gaussian of `sigma` px (periodic), scaled to unit std."""
    white = rng.standard_normal(shape)
    fy, fx = np.fft.fftfreq(shape[0])[:, None], np.fft.rfftfreq(shape[1])[None, :]
    gain = np.exp(-2 * (np.pi * sigma) ** 2 * (fy ** 2 + fx ** 2))
    out = np.fft.irfft2(np.fft.rfft2(white) * gain, s=shape)
    return out / out.std()


def tiles(size: int = 512, seed: int = 0, period: int = 64, grout: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size]
    cells = size // period + 1
    tint = 1 + 0.06 * rng.standard_normal((cells, cells, 1))
    base = np.array([0.72, 0.68, 0.60]) * tint[y // period, x // period]
    mottle = 0.05 * smooth_noise(rng, (size, size), 4)[..., None] + 0.015 * rng.standard_normal((size, size, 1))
    img = base + mottle
    line = ((y % period) < grout) | ((x % period) < grout)
    img[line] = np.array([0.30, 0.29, 0.27]) + 0.02 * rng.standard_normal((int(line.sum()), 1))
    return np.clip(img, 0, 1).astype(np.float32)


def planks(size: int = 512, seed: int = 0, width: int = 48) -> np.ndarray:
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size]
    row = y // width
    rows = size // width + 1
    length = rng.integers(160, 320, rows)
    start = rng.integers(0, 320, rows)
    piece = (x + start[row]) // length[row]
    tone = 1 + 0.10 * rng.standard_normal((rows, size))
    warp = 6 * smooth_noise(rng, (size, size), 24)
    grain = 0.5 + 0.5 * np.sin(2 * np.pi * (y + warp) / 7.0) * (0.6 + 0.4 * smooth_noise(rng, (size, size), 3))
    base = np.array([0.55, 0.36, 0.20]) * tone[row, piece][..., None]
    img = base * (0.85 + 0.15 * grain[..., None]) + 0.01 * rng.standard_normal((size, size, 1))
    joint = ((y % width) < 2) | (((x + start[row]) % length[row]) < 2)
    img[joint] *= 0.4
    return np.clip(img, 0, 1).astype(np.float32)


def _joints(ids: np.ndarray) -> np.ndarray:
    """Pixels whose right or lower neighbour belongs to another piece."""
    edge = np.zeros(ids.shape, bool)
    edge[:, :-1] |= ids[:, :-1] != ids[:, 1:]
    edge[:-1] |= ids[:-1] != ids[1:]
    return edge


def herringbone(size: int = 512, seed: int = 0, width: int = 16, blocks: int = 4) -> np.ndarray:
    """Blocks width x (blocks * width): horizontal block k of a strip covers cells [k, k + n) x
    [k, k + 1) of the width grid, vertical block k covers [k, k + 1) x [k + 1, k + 1 + n), and the
    strips repeat by (n, -n); a cell's piece follows from x - y modulo 2n."""
    rng = np.random.default_rng(seed)
    n = blocks
    y, x = np.mgrid[:size, :size]
    cx, cy = x // width, y // width
    a = cx - cy
    m = np.floor_divide(a + n, 2 * n)
    rest = a - 2 * n * m
    horizontal = rest >= 0
    k = np.where(horizontal, cy + n * m, cy + n * m + rest)
    ids = (k * 4099 + m) * 2 + horizontal
    _, piece = np.unique(ids, return_inverse=True)
    shade = 1 + 0.12 * rng.standard_normal(piece.max() + 1)
    grain = 0.04 * smooth_noise(rng, (size, size), 1.5)
    img = np.array([0.58, 0.40, 0.24]) * (shade[piece.reshape(size, size)] + grain)[..., None]
    img[_joints(ids)] *= 0.45
    return np.clip(img, 0, 1).astype(np.float32)


def hexagons(size: int = 512, seed: int = 0, across: int = 56, grout: float = 2.5) -> np.ndarray:
    """Hexagonal tiles `across` px between parallel sides: the nearest point of a triangular
    lattice is the tile, grout where the second nearest is almost as near."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size].astype(np.float64)
    a, b = float(across), across * np.sqrt(3.0)
    cands = []
    for oy, ox in ((0.0, 0.0), (0.5, 0.5)):
        for dj in (0, 1):
            for di in (0, 1):
                j, i = np.floor(y / b - oy) + dj, np.floor(x / a - ox) + di
                cy, cx = (j + oy) * b, (i + ox) * a
                cands.append((np.hypot(y - cy, x - cx), np.rint(2 * cy / b) * 4099 + np.rint(2 * cx / a)))
    dist = np.stack([c[0] for c in cands])
    ids = np.stack([c[1] for c in cands])
    order = np.argsort(dist, axis=0)
    d1, d2 = np.take_along_axis(dist, order[:2], axis=0)
    tile = np.take_along_axis(ids, order[:1], axis=0)[0]
    _, piece = np.unique(tile, return_inverse=True)
    tint = 1 + 0.05 * rng.standard_normal(piece.max() + 1)
    img = np.array([0.66, 0.70, 0.72]) * tint[piece.reshape(size, size)][..., None]
    img = img + 0.03 * smooth_noise(rng, (size, size), 3)[..., None]
    img[(d2 - d1) < grout] = np.array([0.28, 0.28, 0.27])
    return np.clip(img, 0, 1).astype(np.float32)


def carpet(size: int = 512, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    pile = 0.06 * smooth_noise(rng, (size, size), 0.8) + 0.03 * smooth_noise(rng, (size, size), 3)
    tint = 0.015 * smooth_noise(rng, (size, size), 2)[..., None] * np.array([1.0, -0.3, -0.6])
    return np.clip(np.array([0.42, 0.30, 0.30]) + pile[..., None] + tint, 0, 1).astype(np.float32)


def concrete(size: int = 512, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    blotch = 0.05 * smooth_noise(rng, (size, size), 30) + 0.03 * smooth_noise(rng, (size, size), 10)
    grain = 0.02 * smooth_noise(rng, (size, size), 0.7)
    pores = (smooth_noise(rng, (size, size), 1.2) > 3.2) * -0.15
    return np.clip(np.array([0.55, 0.55, 0.53]) + (blotch + grain + pores)[..., None], 0, 1).astype(np.float32)


def noise(size: int = 512, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    lum = sum(a * smooth_noise(rng, (size, size), s) for a, s in ((0.06, 6), (0.05, 2), (0.04, 0.7)))
    tint = 0.02 * smooth_noise(rng, (size, size), 3)[..., None] * np.array([1.0, -0.5, -0.5])
    return np.clip(np.array([0.5, 0.48, 0.45]) + lum[..., None] + tint, 0, 1).astype(np.float32)


def gradient(size: int = 512, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size] / (size - 1)
    t = 0.6 * x + 0.4 * y
    img = np.stack([0.2 + 0.6 * t, 0.3 + 0.4 * t, 0.6 - 0.3 * t], axis=-1)
    return np.clip(img + 0.01 * rng.standard_normal((size, size, 1)), 0, 1).astype(np.float32)


def lighting(size: int, hole: tuple[int, int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Irradiance (H, W, 1) on a size x size floor with the object, and after its removal (E').

    E' is a lamp off the image's upper left corner (the falloff of a point light over a plane: 1.05
    near it, 0.33 in the far corner). E is E' times the object's soft shadow: a Gaussian
    darkening to 35 % at its centre, which lies inside the hole (y0, y1, x0, x1) near its lower right
    corner, so half the shadow falls on the visible floor beside the hole.
    """
    y, x = np.mgrid[:size, :size] / size
    after = 1.05 / (1 + ((x + 0.1) ** 2 + (y + 0.1) ** 2) / 2.07) ** 1.5
    y0, y1, x0, x1 = hole
    cy, cx, sigma = (y0 + 0.8 * (y1 - y0)) / size, (x0 + 0.8 * (x1 - x0)) / size, 0.3 * (y1 - y0) / size
    shadow = 1 - 0.65 * np.exp(-((y - cy) ** 2 + (x - cx) ** 2) / (2 * sigma ** 2))
    return (after * shadow)[..., None].astype(np.float32), after[..., None].astype(np.float32)


TEXTURES = {"tiles": tiles, "planks": planks, "herringbone": herringbone, "hexagons": hexagons, "carpet": carpet,
            "concrete": concrete, "noise": noise, "gradient": gradient}
DEFAULT = ("tiles", "planks", "herringbone", "hexagons", "carpet", "concrete")  # the floors people bring
