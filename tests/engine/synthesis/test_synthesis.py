"""Texture synthesis: pyramids and neighbourhoods against hand-made arrays, determinism, order
independence of on-demand requests, continuation of a periodic texture, masks, errors, progress."""
import numpy as np
import pytest

from addon.errors import Cancelled, DimredError
from addon.synthesis.texture import (
    OrderIndependentSynthesis,
    SynthesisParams,
    fill,
    fill_with_sources,
    neighbourhoods,
    pyramid,
)


def _stripes(size=96, period=8, seed=0):
    """Vertical and horizontal stripes of `period` in two channels, with faint noise."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size]
    img = np.stack([0.2 + 0.6 * ((x % period) < period // 2), 0.3 + 0.4 * ((y % period) < period // 2),
                    np.full((size, size), 0.5)], axis=-1)
    return (img + rng.normal(0, 0.02, img.shape)).astype(np.float32)


def _noise(size=64, seed=0):
    rng = np.random.default_rng(seed)
    white = rng.standard_normal((size + 4, size + 4, 3))
    smooth = sum(white[dy:dy + size, dx:dx + size] for dy in range(5) for dx in range(5)) / 5
    return (0.5 + 0.1 * smooth).astype(np.float32)


def _square(size, lo, hi):
    m = np.zeros((size, size), bool)
    m[lo:hi, lo:hi] = True
    return m


def _highpass_std(img, mask):
    blur = (img + np.roll(img, 1, 0) + np.roll(img, -1, 0) + np.roll(img, 1, 1) + np.roll(img, -1, 1)) / 5
    return (img - blur)[mask].std()


def test_pyramid_matches_hand_computed_binomial_levels():
    impulse = np.zeros((5, 5, 1), np.float32)
    impulse[2, 2] = 1
    (v0, _w0), (v1, w1) = pyramid(impulse, np.ones((5, 5), np.float32), 2)
    assert v1.shape == (3, 3, 1) and np.array_equal(v0, impulse)
    # centre: the full 5x5 footprint, weight (6/16)^2; corner: only taps 0..2 of each axis are
    # inside (weight (11/16)^2) and the impulse sits at tap offset 2 (weight (1/16)^2)
    assert w1[1, 1] == pytest.approx(1) and v1[1, 1, 0] == pytest.approx(36 / 256)
    assert w1[0, 0] == pytest.approx((11 / 16) ** 2) and v1[0, 0, 0] == pytest.approx(1 / 121)
    assert w1[0, 1] == pytest.approx(11 / 16)  # rows 0..2 inside, columns all inside (fine 0..4)


def test_pyramid_ignores_pixels_without_weight():
    img = np.full((4, 4, 2), 3.0, np.float32)
    weight = np.ones((4, 4), np.float32)
    img[0, 0], weight[0, 0] = np.nan, 0  # a don't-care pixel must not leak into the level above
    levels = pyramid(img, weight, 3)
    assert [v.shape for v, _ in levels] == [(4, 4, 2), (2, 2, 2), (1, 1, 2)]
    assert all(np.allclose(v, 3) for v, _ in levels[1:])
    assert levels[1][1][0, 0] == pytest.approx((11 / 16) ** 2 - (6 / 16) ** 2)


def test_neighbourhoods_match_hand_made_windows():
    level = np.arange(9, dtype=np.float32).reshape(3, 3, 1)
    ok = np.ones((3, 3), bool)
    ok[1, 1] = False
    vec, valid = neighbourhoods(level, ok, None, np.array([0, 2]), np.array([0, 1]), 3)
    # pixel (0, 0): rows -1..1, columns -1..1; (1, 1) is not ok
    assert vec[0].tolist() == [0, 0, 0, 0, 0, 1, 0, 3, 0]
    assert valid[0].tolist() == [False, False, False, False, True, True, False, True, False]
    assert vec[1].tolist() == [3, 0, 5, 6, 7, 8, 0, 0, 0]
    assert valid[1].tolist() == [True, False, True, True, True, True, False, False, False]


def test_neighbourhoods_sample_the_coarser_level_bilinearly():
    level = np.zeros((4, 4, 1), np.float32)
    coarse = np.array([[10, 20], [30, 40]], np.float32)[..., None]
    vec, valid = neighbourhoods(level, np.ones((4, 4), bool), (coarse, np.ones((2, 2), bool)),
                                np.array([1, 0]), np.array([1, 2]), 1)
    # fine (1, 1) lies between all four coarse pixels; its coarse neighbours at +-2 fine pixels
    # leave the coarse image, except for the centre
    assert vec[0, 1:].tolist() == [0, 0, 0, 0, 25, 0, 0, 0, 0]
    assert valid[0, 1:].tolist() == [False] * 4 + [True] + [False] * 4
    # fine (0, 2) is coarse (0, 1) exactly; (0, 0) and (1, 1), (1, 0) are 2 fine pixels away
    assert vec[1, 1:].tolist() == [0, 0, 0, 10, 20, 0, 30, 40, 0]
    coarse_ok = np.array([[True, False], [True, True]])
    _, valid = neighbourhoods(level, np.ones((4, 4), bool), (coarse, coarse_ok), np.array([0]), np.array([2]), 1)
    assert valid[0, 1:].tolist() == [False, False, False, True, False, False, True, True, False]


@pytest.mark.parametrize("search", ["accelerated", "exhaustive"])
def test_same_seed_same_fill_other_seed_other_fill(search):
    img, hole = _noise(), _square(64, 24, 40)
    params = SynthesisParams(search=search, offsets=0)
    a = fill(img, ~hole, hole, params, seed=3)
    b = fill(img, ~hole, hole, params, seed=3)
    c = fill(img, ~hole, hole, params, seed=4)
    assert np.array_equal(a, b)
    assert not np.array_equal(a[hole], c[hole])


@pytest.mark.parametrize("search", ["accelerated", "exhaustive"])
def test_pixels_on_demand_in_any_order_equal_the_full_fill(search):
    img, hole = _noise(seed=1), _square(64, 20, 44)
    hole[30:34, 10:20] = True  # not a rectangle: a spur to the side
    known = ~hole
    known[:, 60:] = False  # a don't-care band
    params = SynthesisParams(search=search)
    full = fill(img, known, hole, params, seed=7)
    ys, xs = np.nonzero(hole)
    order = np.random.default_rng(0).permutation(len(ys))

    scattered = OrderIndependentSynthesis(img, known, hole, params, seed=7)
    single = scattered.pixels(0, ys[order[:1]], xs[order[:1]])  # one pixel first, alone
    parts = [scattered.pixels(0, ys[part], xs[part]) for part in np.array_split(order[::-1], 5)]
    assert np.array_equal(single, full[ys[order[:1]], xs[order[:1]]])
    assert np.array_equal(np.concatenate(parts), full[ys[order[::-1]], xs[order[::-1]]])

    coarse_first = OrderIndependentSynthesis(img, known, hole, params, seed=7)
    coarse_first.pixels(1, *np.nonzero(_square(32, 12, 16)))  # part of a coarser level first
    assert np.array_equal(coarse_first.pixels(0, ys, xs), full[ys, xs])


def test_periodic_texture_continues_its_phase_across_the_hole():
    img, hole = _stripes(), _square(96, 32, 64)
    out = fill(img, ~hole, hole)
    for c in (0, 1):  # the stripes of both directions
        truth, got = img[..., c][hole] - img[..., c][hole].mean(), out[..., c][hole] - out[..., c][hole].mean()
        assert np.corrcoef(truth, got)[0, 1] > 0.8


def test_known_pixels_unchanged_dont_care_ignored_no_nan():
    img, hole = _noise(seed=2), _square(64, 16, 40)
    known = ~hole
    known[40:48, :] = False  # don't care, next to the hole, holding NaN: it must not be used
    img[40:48, :] = np.nan
    out = fill(img, known, hole)
    assert np.isfinite(out[hole]).all()
    assert np.array_equal(out[known], img[known])
    assert np.isnan(out[40:48]).all()
    assert abs(out[hole].mean() - img[known].mean()) < 0.05


def test_accelerated_search_is_as_good_as_exhaustive_on_noise():
    img, hole = _noise(seed=5), _square(64, 20, 44)
    truth_hf = _highpass_std(img, hole)
    for search in ("accelerated", "exhaustive"):
        # a 5 x 5 window: with the default 7 x 7 this 64 x 64 exemplar has too few windows to match
        # well, and both searches give a detail ratio of 1.3-1.45
        out = fill(img, ~hole, hole, SynthesisParams(search=search, neighbourhood=5))
        assert 0.7 < _highpass_std(out, hole) / truth_hf < 1.3, search
        assert abs(out[hole].mean() - img[~hole].mean()) < 0.05, search


def test_separate_exemplar_is_the_only_source_of_values():
    exemplar = _stripes(48)
    img, hole = np.zeros((40, 40, 3), np.float32), _square(40, 4, 36)
    out = fill(img, ~hole, hole, SynthesisParams(smooth_seams=False), exemplar=exemplar)
    values = {tuple(v) for v in exemplar.reshape(-1, 3)}
    assert all(tuple(v) in values for v in out[hole])


def test_an_exemplar_too_small_to_hold_the_hole_shifted_starts_from_noise():
    # No offset can qualify when the exemplar is smaller than the hole's ring: the fill must
    # start from noise drawn from it instead of failing.
    rng = np.random.default_rng(0)
    img = rng.random((48, 48, 3)).astype(np.float32)
    hole = _square(48, 16, 32)
    exemplar = rng.random((20, 20, 3)).astype(np.float32)
    out = fill(img, ~hole, hole, SynthesisParams(), exemplar=exemplar)
    assert np.isfinite(out).all() and np.array_equal(out[~hole], img[~hole])


def test_smooth_seams_match_the_fill_to_the_surrounding_shade():
    texture = _noise(seed=3)
    img, hole = texture + 0.2, _square(64, 16, 48)  # the exemplar is 0.2 darker than the surroundings
    for smooth, expected in ((False, texture.mean()), (True, img[~hole].mean())):
        out = fill(img, ~hole, hole, SynthesisParams(smooth_seams=smooth), exemplar=texture)
        assert abs(out[hole].mean() - expected) < 0.05, smooth


@pytest.mark.parametrize("size, valid", [(4, None), (32, np.zeros((32, 32), bool))])
def test_too_small_or_empty_exemplar_raises(size, valid):
    img, hole = _noise(), _square(64, 24, 40)
    with pytest.raises(DimredError, match="exemplar"):
        fill(img, ~hole, hole, exemplar=_noise(size), exemplar_valid=valid)


def test_nothing_known_raises():
    img = _noise()
    with pytest.raises(DimredError, match="nothing is known"):
        fill(img, np.zeros((64, 64), bool), _square(64, 24, 40))


def test_cancel_raises_cancelled_during_the_fill():
    img, hole = _noise(), _square(64, 24, 40)
    calls = []

    def cancel():
        calls.append(1)
        return len(calls) > 3

    with pytest.raises(Cancelled):
        fill(img, ~hole, hole, cancel=cancel)


def test_progress_goes_coarse_to_fine_with_full_size_previews():
    img, hole = _stripes(), _square(96, 32, 64)
    seen = []
    # a 5 x 5 window gives this 96 px image 3 levels (a 7 x 7 one, 2: the coarsest keeps 4 windows across)
    out = fill(img, ~hole, hole, SynthesisParams(neighbourhood=5),
               progress=lambda level, preview: seen.append((level, preview.copy())))
    levels = [level for level, _ in seen]
    assert len(levels) >= 3 and levels == sorted(levels, reverse=True) and levels[-1] == 0
    for _, preview in seen:
        assert preview.shape == img.shape and np.array_equal(preview[~hole], img[~hole])
    assert np.array_equal(seen[-1][1], out)
    # each finer level adds detail: the preview's high-pass energy in the hole grows
    detail = [_highpass_std(preview, hole) for _, preview in seen]
    assert detail[0] < detail[-1] and detail[-2] < detail[-1]


def test_sources_are_the_known_pixels_each_hole_pixel_copies():
    img = _noise(64)
    hole = _square(64, 24, 40)
    out, sources = fill_with_sources(img, ~hole, hole, SynthesisParams(smooth_seams=False), seed=2)
    assert np.array_equal(sources[..., 0] >= 0, hole)
    ys, xs = sources[hole].T
    assert not hole[ys, xs].any()
    np.testing.assert_array_equal(out[hole], img[ys, xs])
    np.testing.assert_array_equal(out, fill(img, ~hole, hole, SynthesisParams(smooth_seams=False), seed=2))
