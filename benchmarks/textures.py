"""Procedural floor textures for the synthesis benchmark: seeded, numpy only, RGB float32 in 0..1.

tiles: 64 px tiles with 3 px grout and mottled, slightly varying tile colours; planks: wood planks
48 px wide with grain and staggered joints; noise: stochastic gravel-like multi-scale noise;
gradient: a smooth diagonal gradient with faint noise.

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


TEXTURES = {"tiles": tiles, "planks": planks, "noise": noise, "gradient": gradient}
