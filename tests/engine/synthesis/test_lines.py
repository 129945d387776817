"""Interpolation along the lines of a raster (planks): against hand-made arrays."""
import numpy as np
import pytest

from addon.synthesis.lines import across_detail, along_mean, interpolate_lines, sharpened_across


def _plank_shades(seed=0, shape=(40, 90)):
    """Rows of random shades (planks along the columns) in three channels, and a gap across them."""
    rng = np.random.default_rng(seed)
    image = np.repeat(rng.random(shape[0])[:, None], shape[1], axis=1)[..., None] * np.array([1.0, 0.8, 0.6])
    known = np.ones(shape, bool)
    known[5:35, 30:60] = False
    return image.astype(np.float32), known


@pytest.mark.parametrize("axis", [0, 1])
def test_each_line_keeps_its_own_value_and_a_ramp_along_it(axis):
    image, known = _plank_shades()
    ramp = image * (1 + 0.01 * np.arange(image.shape[1]))[None, :, None]
    if axis == 0:
        image, ramp, known = image.transpose(1, 0, 2), ramp.transpose(1, 0, 2), known.T
    got = interpolate_lines(image, known, axis=axis, ends=4)
    assert got.reached.all()
    np.testing.assert_allclose(got.values[~known], image[~known], atol=1e-6)
    exact = interpolate_lines(ramp, known, axis=axis, ends=0)  # a mean over the ends would bend a ramp
    np.testing.assert_allclose(exact.values[~known], ramp[~known], rtol=1e-5)


def test_one_end_seen_gives_its_value_and_none_seen_reaches_nothing():
    image, known = _plank_shades()
    known[:, 60:] = False  # lines run off the right edge: only their left end is seen
    known[20] = False  # this line is seen nowhere
    got = interpolate_lines(image, known, axis=1, ends=0)
    np.testing.assert_allclose(got.values[10, 30:], np.broadcast_to(image[10, 29], (60, 3)), atol=1e-6)
    assert not got.reached[20].any() and got.reached[~known & (np.arange(40) != 20)[:, None]].all()


def test_the_ends_mean_takes_the_noise_of_the_border_pixel_out():
    image, known = _plank_shades(seed=1)
    noisy = image + 0.05 * np.random.default_rng(2).standard_normal(image.shape).astype(np.float32)

    def error(ends):
        return float(np.abs(interpolate_lines(noisy, known, axis=1, ends=ends).values - image)[~known].mean())

    assert error(6) < 0.5 * error(0)


def test_along_mean_is_the_mean_over_the_mask_within_the_radius():
    rng = np.random.default_rng(3)
    image = rng.random((7, 20, 2)).astype(np.float32)
    mask = rng.random((7, 20)) > 0.3
    got = along_mean(image, mask, axis=1, radius=3)
    for r in range(7):
        for c in range(20):
            sel = np.flatnonzero(mask[r, max(c - 3, 0):c + 4]) + max(c - 3, 0)
            want = image[r, sel].mean(axis=0) if len(sel) else np.zeros(2)
            np.testing.assert_allclose(got[r, c], want, rtol=1e-5, atol=1e-6)
    np.testing.assert_allclose(along_mean(image.transpose(1, 0, 2), mask.T, axis=0, radius=3),
                               got.transpose(1, 0, 2), rtol=1e-6)


def _blurred_across(image, axis):
    """`image` blurred twice across its lines by [1/4, 1/2, 1/4] (edges repeated): the two
    bilinear lookups a fill goes through, panorama to raster and back."""
    for _ in range(2):
        image = image - 0.75 * across_detail(image, axis=axis)  # 1/4, 1/2, 1/4 = v - 3/4 (v - mean3)
    return image


@pytest.mark.parametrize("axis", [0, 1])
def test_sharpening_across_the_lines_restores_blurred_seams_and_leaves_the_rest(axis):
    _, known = _plank_shades()
    seams = np.where(np.arange(40) % 6 == 0, 0.4, 1.0)  # planks 6 px wide, each with its own shade
    shade = np.repeat(0.3 + 0.4 * np.random.default_rng(4).random(7), 6)[:40] * seams
    along = 1 + 0.01 * np.arange(90)  # and a change along them
    ramp = (shade[:, None] * along[None, :])[..., None] * np.array([1.0, 0.8, 0.6], np.float32)
    flat = np.broadcast_to(along[None, :, None], ramp.shape).astype(np.float32)
    if axis == 0:
        ramp, flat, known = ramp.transpose(1, 0, 2), flat.transpose(1, 0, 2), known.T
    blurred = _blurred_across(ramp, axis)
    got = sharpened_across(blurred, ~known, axis=axis, gain=2.0)
    hole = ~known
    inner = hole & np.roll(hole, 1, axis=1 - axis) & np.roll(hole, -1, axis=1 - axis)  # neighbours across in it
    truth = across_detail(ramp, axis=axis)[inner].ravel()

    def spread_and_correlation(x):
        d = across_detail(x, axis=axis)[inner].ravel()
        return d.std() / truth.std(), np.corrcoef(d, truth)[0, 1]

    (spread_before, correlation_before), (spread, correlation) = map(spread_and_correlation, (blurred, got))
    assert spread > 1.5 * spread_before and correlation > correlation_before + 0.05
    assert np.abs(got - ramp)[inner].mean() <= np.abs(blurred - ramp)[inner].mean()
    np.testing.assert_array_equal(got[known], blurred[known])
    # a field that changes along the lines only holds nothing across them to sharpen
    np.testing.assert_allclose(sharpened_across(flat, ~known, axis=axis, gain=2.0), flat, atol=1e-6)
