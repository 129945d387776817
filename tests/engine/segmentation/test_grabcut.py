"""segment_object on synthetic windows: a box with a lit top, a shaded side, a soft shadow and a
lamp beside it on a noisy checker floor, and a leg two pixels wide; proxies exact, shifted,
scaled, thin, or over plain floor."""
from __future__ import annotations

import numpy as np
import pytest

from addon.segmentation.grabcut import segment_object
from addon.segmentation.masks import dilate, erode
from tests.engine.segmentation.synthetic_object import (
    BOX_EXTENT,
    LAMP,
    LEG_EXTENT,
    box_window,
    iou,
    leg_window,
    rectangle,
    scaled,
)

BAND = 6  # 10 % of the box


@pytest.fixture(scope="module")
def window():
    return box_window()


def _proxies(shape: tuple[int, int]) -> dict[str, np.ndarray]:
    exact = rectangle(shape, *BOX_EXTENT)
    return {"exact": exact, "shifted 3 px": np.roll(exact, 3, axis=1),
            "shifted 3 px down and left": np.roll(np.roll(exact, 3, axis=0), -3, axis=1),
            "scaled 0.9": rectangle(shape, *scaled(BOX_EXTENT, 0.9)),
            "scaled 1.1": rectangle(shape, *scaled(BOX_EXTENT, 1.1))}


@pytest.mark.parametrize("name", list(_proxies((1, 1))))
def test_the_box_is_found_from_rough_proxies_without_its_shadow_or_the_lamp(window, name):
    proxy = _proxies(window.truth.shape)[name]
    seg = segment_object(window.image, proxy, band=BAND)
    assert iou(seg.object, window.truth) >= 0.95
    assert iou(seg.object, window.truth) > iou(proxy, window.truth) or name == "exact"
    assert not (seg.object & window.shadow).any()
    assert not seg.object[window.image.min(axis=-1) >= LAMP / 2].any()


@pytest.mark.parametrize("shift", [0, 1])
def test_a_leg_two_pixels_wide_is_found(shift):
    leg = leg_window()
    seg = segment_object(leg.image, np.roll(leg.truth, shift, axis=1), band=3)
    assert iou(seg.object, leg.truth) >= 0.8


@pytest.mark.parametrize(("factor", "down"), [(1.06, 5), (0.94, -5)])
def test_a_wide_band_is_decided_coarse_to_fine(factor, down):
    big = box_window(size=240, seed=5)
    extent = tuple(2 * v for v in BOX_EXTENT)
    proxy = np.roll(rectangle(big.truth.shape, *scaled(extent, factor)), down, axis=0)
    seg = segment_object(big.image, proxy, band=34)  # halved twice, to 9 px
    assert iou(seg.object, big.truth) >= 0.95
    assert not (seg.object & big.shadow).any()


def test_pixels_off_the_band_keep_the_proxy_s_label_and_alpha_agrees(window):
    proxy = rectangle(window.truth.shape, *scaled(BOX_EXTENT, 0.9))
    seg = segment_object(window.image, proxy, band=BAND)
    assert np.array_equal(seg.band, dilate(proxy, BAND) & ~erode(proxy, BAND))
    assert np.array_equal(seg.object[~seg.band], proxy[~seg.band])
    assert np.array_equal(seg.alpha[~seg.band], proxy[~seg.band].astype(np.float32))
    assert seg.alpha.dtype == np.float32 and seg.alpha.min() >= 0.0 and seg.alpha.max() <= 1.0
    assert np.array_equal(seg.object, seg.alpha >= 0.5)
    assert ((seg.alpha > 0.0) & (seg.alpha < 1.0)).any()


def test_same_input_same_output(window):
    proxy = np.roll(rectangle(window.truth.shape, *BOX_EXTENT), 3, axis=1)
    a = segment_object(window.image, proxy, band=BAND)
    b = segment_object(window.image.copy(), proxy.copy(), band=BAND)
    assert np.array_equal(a.alpha, b.alpha) and np.array_equal(a.object, b.object)
    assert (a.outline_contrast, a.separation) == (b.outline_contrast, b.separation)


def test_a_proxy_over_plain_floor_scores_low(window):
    on_object = segment_object(window.image, rectangle(window.truth.shape, *BOX_EXTENT), band=BAND)
    floor_only = segment_object(window.image, rectangle(window.truth.shape, 94, 116, 4, 40), band=4)
    assert on_object.outline_contrast > 1.8 and on_object.separation > 5.0
    assert floor_only.outline_contrast < 1.3 and floor_only.separation < 1.0
    leg = leg_window()
    empty = np.zeros_like(leg.truth)
    empty[int(LEG_EXTENT[0]):int(LEG_EXTENT[1]), 60:62] = True  # the leg's shape over bare floor
    off = segment_object(leg.image, empty, band=3)
    assert off.separation < 1.0


def test_bad_arguments_are_refused(window):
    proxy = rectangle(window.truth.shape, *BOX_EXTENT)
    with pytest.raises(ValueError, match="band"):
        segment_object(window.image, proxy, band=0)
    with pytest.raises(ValueError, match="no pixel"):
        segment_object(window.image, np.zeros_like(proxy), band=BAND)
