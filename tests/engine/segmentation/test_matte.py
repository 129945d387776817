"""The matte's 0.5 contour finds an edge rendered by area coverage to a fraction of a pixel,
noisy or not, tilted or not, with the binary labelling a pixel off; it leaves the labelling
alone where the two sides look alike or a lamp glows beside the outline."""
from __future__ import annotations

import numpy as np

from addon.segmentation.matte import soft_alpha

OBJECT = np.array([0.08, 0.12, 0.40])
FLOOR = np.array([0.45, 0.38, 0.30])


def _edge(shape: tuple[int, int], x0: float, slope: float) -> np.ndarray:
    """Share of each pixel left of the line x = x0 + slope y, by 16 x 16 supersampling."""
    s = (np.arange(16) + 0.5) / 16
    rows = np.arange(shape[0])[:, None, None, None] + s[None, None, :, None]
    cols = np.arange(shape[1])[None, :, None, None] + s[None, None, None, :]
    return (cols < x0 + slope * rows).mean(axis=(2, 3))


def _render(coverage: np.ndarray, *, noise: float = 0.0, seed: int = 0) -> np.ndarray:
    clean = coverage[..., None] * OBJECT + (1.0 - coverage[..., None]) * FLOOR
    rng = np.random.default_rng(seed)
    return np.maximum(clean * (1.0 + noise * rng.standard_normal(clean.shape)), 0.0).astype(np.float32)


def _contour(alpha: np.ndarray) -> np.ndarray:
    """x of the 0.5 crossing in each row (alpha falling left to right), linear between pixel centres."""
    c = np.argmax(alpha < 0.5, axis=1) - 1  # last pixel at or above 0.5
    rows = np.arange(len(alpha))
    a, b = alpha[rows, c], alpha[rows, c + 1]
    return c + 0.5 + (a - 0.5) / (a - b)


def test_the_half_contour_of_a_straight_edge_is_within_0_15_px():
    shape = (40, 48)
    for x0 in (20.0, 20.25, 20.5, 20.8):
        coverage = _edge(shape, x0, 0.0)
        exact = coverage >= 0.5
        wide = exact | np.pad(exact[:, :-1], ((0, 0), (1, 0)))
        for labels in (exact, wide):  # the labelling exact, or a pixel too wide
            alpha = soft_alpha(_render(coverage), labels, np.ones(shape, dtype=bool))
            assert np.all(np.abs(_contour(alpha) - x0) < 0.15), (x0, labels.sum())


def test_the_half_contour_of_a_tilted_edge_is_within_0_15_px():
    shape = (48, 48)
    coverage = _edge(shape, 14.3, 0.37)
    alpha = soft_alpha(_render(coverage), coverage >= 0.5, np.ones(shape, dtype=bool))
    truth = 14.3 + 0.37 * (np.arange(shape[0]) + 0.5)
    assert np.all(np.abs(_contour(alpha) - truth) < 0.15)


def test_noise_leaves_the_contour_unbiased():
    shape = (200, 48)
    coverage = _edge(shape, 23.6, 0.0)
    alpha = soft_alpha(_render(coverage, noise=0.2, seed=1), coverage >= 0.5, np.ones(shape, dtype=bool))
    error = _contour(alpha) - 23.6
    assert abs(error.mean()) < 0.05
    assert np.median(np.abs(error)) < 0.15


def test_alpha_is_binary_off_the_outline_and_outside_the_band():
    shape = (30, 40)
    coverage = _edge(shape, 20.4, 0.0)
    labels = coverage >= 0.5
    decided = np.zeros(shape, dtype=bool)
    decided[:20] = True
    alpha = soft_alpha(_render(coverage), labels, decided)
    assert alpha.dtype == np.float32
    assert np.array_equal(alpha[20:], labels[20:].astype(np.float32))
    assert np.all(alpha[:, :17] == 1.0) and np.all(alpha[:, 24:] == 0.0)
    assert np.all((alpha[:20, 20] > 0.3) & (alpha[:20, 20] < 0.5))


def test_alike_sides_and_a_lamp_keep_the_labelling():
    shape = (30, 40)
    coverage = _edge(shape, 20.5, 0.0)
    labels = coverage >= 0.5
    everywhere = np.ones(shape, dtype=bool)
    # Two sides 2 % apart under 20 % noise: any share would be noise.
    rng = np.random.default_rng(2)
    alike = (np.where(labels[..., None], 0.51, 0.50) * (1.0 + 0.2 * rng.standard_normal((*shape, 3))))
    assert np.array_equal(soft_alpha(alike.astype(np.float32), labels, everywhere), labels.astype(np.float32))
    # A lamp four pixels right of the edge: the background's median ignores it, and the pixels its
    # glow reaches after smoothing are no mix of the two sides.
    image = _render(coverage)
    image[10:14, 24:26] = 3000.0
    alpha = soft_alpha(image, labels, everywhere)
    assert np.all(alpha[:, 22:] == 0.0)
    assert np.all(np.abs(_contour(alpha) - 20.5) < 0.15)
