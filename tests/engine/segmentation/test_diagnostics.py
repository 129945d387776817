"""The diagnostics picture: size by whole factors within the bounds, tints where the proxy and
the segmentation disagree, outlines in their colours."""
from __future__ import annotations

import numpy as np

from addon.segmentation.diagnostics import diagnostics_picture

RED, BLUE, CYAN, YELLOW = (np.array(c) for c in ([255, 0, 0], [0, 0, 255], [0, 255, 255], [255, 255, 0]))


def _case(h: int = 40, w: int = 50) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A grey floor with a lamp; the proxy is too small on the left and too large on the right."""
    image = np.full((h, w, 3), 0.2, dtype=np.float32)
    image[2:4, 2:4] = 5000.0
    proxy = np.zeros((h, w), dtype=bool)
    proxy[10:30, 15:40] = True
    segmented = np.zeros((h, w), dtype=bool)
    segmented[10:30, 10:35] = True
    return image, proxy, segmented


def _closest(pixel: np.ndarray) -> np.ndarray:
    """Which of red, blue, cyan, yellow, grey a pixel is nearest to in hue."""
    p = pixel.astype(float)
    p = p - p.min()
    colours = np.stack([RED, BLUE, CYAN, YELLOW, np.zeros(3)]).astype(float)
    return np.argmin(np.linalg.norm(colours / 255.0 - p / max(p.max(), 1.0), axis=1))


def test_small_windows_are_enlarged_by_a_whole_factor_into_the_bounds():
    image, proxy, segmented = _case()
    picture = diagnostics_picture(image, proxy, segmented)
    assert picture.dtype == np.uint8
    assert picture.shape == (40 * 11, 50 * 11, 3)  # the least factor reaching 512 px
    assert diagnostics_picture(image, proxy, segmented, min_width=100, max_width=120).shape == (80, 100, 3)
    assert diagnostics_picture(image, proxy, segmented, min_width=1000, max_width=560).shape == (440, 550, 3)


def test_large_windows_are_reduced_by_averaging_blocks():
    image, proxy, segmented = _case(300, 2100)
    picture = diagnostics_picture(image, proxy, segmented)
    assert picture.shape == (100, 700, 3)  # 3 x 3 blocks: the least factor within 1024 px
    assert picture.dtype == np.uint8


def test_tints_and_outlines_are_where_the_masks_say():
    image, proxy, segmented = _case()
    k = 11
    picture = diagnostics_picture(image, proxy, segmented)

    def at(row: float, col: float) -> np.ndarray:
        return picture[int(row * k), int(col * k)]

    assert _closest(at(20.5, 12.5)) == 0  # segmented, not proxy: red
    assert _closest(at(20.5, 37.5)) == 1  # proxy, not segmented: blue
    grey = at(20.5, 25.5)  # both agree: the picture itself
    assert grey[0] == grey[1] == grey[2] and 0 < grey[0] < 255
    assert np.array_equal(at(5.5, 45.5), grey)  # neither: the same floor
    assert np.array_equal(picture[20 * k, 15 * k], CYAN)  # proxy's outline, one pixel after scaling
    assert not np.array_equal(picture[20 * k, 15 * k + 1], CYAN)
    assert np.array_equal(picture[20 * k, 10 * k], YELLOW)  # segmentation's outline
    assert np.array_equal(picture[20 * k, 35 * k - 1], YELLOW)
    # The lamp stays a colour rather than flooding the picture, and the floor is not black.
    assert at(2.5, 2.5).min() > 200 and at(20.5, 25.5).max() > 60
