"""Synthetic windows for the segmentation tests: a box with a lit top and a shaded side (or a
thin leg) on a checker floor, a soft shadow beside it, a lamp far brighter than everything, and
multiplicative noise of the size Cycles leaves at a few dozen samples per pixel."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FLOOR = (np.array([0.30, 0.24, 0.18]), np.array([0.22, 0.19, 0.15]))
BOX = np.array([0.10, 0.16, 0.42])
LAMP = 3000.0


@dataclass(frozen=True)
class Window:
    image: np.ndarray  # (h, w, 3) float32
    truth: np.ndarray  # (h, w) bool: the object
    shadow: np.ndarray  # (h, w) bool: floor darkened to under 60 %


def rectangle(shape: tuple[int, int], top: float, bottom: float, left: float, right: float) -> np.ndarray:
    """Pixels whose centre lies in [top, bottom) x [left, right)."""
    rows = np.arange(shape[0])[:, None] + 0.5
    cols = np.arange(shape[1])[None, :] + 0.5
    return (rows >= top) & (rows < bottom) & (cols >= left) & (cols < right)


def scaled(box: tuple[float, float, float, float], factor: float) -> tuple[float, float, float, float]:
    """The rectangle (top, bottom, left, right) scaled about its centre."""
    top, bottom, left, right = box
    cy, cx = (top + bottom) / 2, (left + right) / 2
    return (cy + (top - cy) * factor, cy + (bottom - cy) * factor, cx + (left - cx) * factor,
            cx + (right - cx) * factor)


def floor(shape: tuple[int, int], *, cell: int = 8) -> np.ndarray:
    rows, cols = np.indices(shape)
    odd = ((rows // cell + cols // cell) % 2).astype(bool)
    return np.where(odd[..., None], FLOOR[1], FLOOR[0])


def finish(clean: np.ndarray, *, noise: float, seed: int) -> np.ndarray:
    """Multiplicative Gaussian noise, clipped at zero radiance."""
    rng = np.random.default_rng(seed)
    return np.maximum(clean * (1.0 + noise * rng.standard_normal(clean.shape)), 0.0).astype(np.float32)


BOX_EXTENT = (30.0, 90.0, 35.0, 85.0)  # top, bottom, left, right in a 120 x 120 window


def box_window(*, size: int = 120, noise: float = 0.2, seed: int = 0, lamp: bool = True) -> Window:
    """A box (BOX_EXTENT scaled to `size`) with a lighter top face and a darker right face, its
    soft shadow on the floor to the right, and a lamp 5 px above it."""
    shape = (size, size)
    s = size / 120.0
    top, bottom, left, right = (v * s for v in BOX_EXTENT)
    image = floor(shape, cell=max(2, round(8 * s)))
    rows, cols = np.indices(shape) + 0.5
    # The shadow falls off smoothly over ~8 px from the box's right face and its bottom half.
    reach = np.maximum(cols - right, 0.0) / (25.0 * s) + np.maximum((top + bottom) / 2 - rows, 0.0) / (8.0 * s)
    darkening = 0.7 * np.clip(1.0 - reach, 0.0, 1.0) * (cols >= right) * (rows < bottom + 4 * s)
    image = image * (1.0 - darkening)[..., None]
    truth = rectangle(shape, top, bottom, left, right)
    image[truth] = BOX
    image[rectangle(shape, top, top + 12 * s, left, right)] = BOX * 1.6
    image[rectangle(shape, top, bottom, right - 10 * s, right)] = BOX * 0.5
    if lamp:
        image[rectangle(shape, top - 9 * s, top - 5 * s, (left + right) / 2, (left + right) / 2 + 4 * s)] = LAMP
    return Window(image=finish(image, noise=noise, seed=seed), truth=truth, shadow=darkening > 0.4)


LEG_EXTENT = (20.0, 100.0, 40.0, 42.0)  # a leg 2 px wide


def leg_window(*, noise: float = 0.2, seed: int = 0) -> Window:
    """A dark wooden leg two pixels wide standing on the floor of a 120 x 80 window."""
    shape = (120, 80)
    image = floor(shape)
    truth = rectangle(shape, *LEG_EXTENT)
    image[truth] = np.array([0.06, 0.035, 0.02])
    return Window(image=finish(image, noise=noise, seed=seed), truth=truth, shadow=np.zeros(shape, dtype=bool))


def iou(a: np.ndarray, b: np.ndarray) -> float:
    return float((a & b).sum() / (a | b).sum())
