"""A picture of how the segmentation differs from the proxy, for the user to judge the fit.

The window is tone-mapped for display and enlarged by whole pixels (an object in a 1K panorama
is some fifty pixels across); red marks object the proxy misses, blue proxy over background, a
cyan line the proxy's outline and a yellow one the segmented outline.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .masks import outline

if TYPE_CHECKING:
    from .seen import SeenObject

_LUMINANCE = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
_MISSED = np.array([1.0, 0.15, 0.1], dtype=np.float32)  # red: object outside the proxy
_EXCESS = np.array([0.15, 0.35, 1.0], dtype=np.float32)  # blue: proxy over background
_PROXY_LINE = np.array([0.0, 1.0, 1.0], dtype=np.float32)  # cyan
_OBJECT_LINE = np.array([1.0, 1.0, 0.0], dtype=np.float32)  # yellow
_TINT = 0.45  # share of the tint colour over the picture


def picture_of(seen: SeenObject) -> np.ndarray:
    """The diagnostics picture of the object as the photograph showed it (uint8 RGB): its window
    with the proxy and the segmented outline marked (the object as shown where no segmentation
    ran)."""
    segmented = seen.segmentation.object if seen.segmentation is not None else seen.shown
    return diagnostics_picture(seen.image, seen.proxy, segmented)


def diagnostics_picture(image: np.ndarray, proxy: np.ndarray, segmented: np.ndarray, *,
                        min_width: int = 512, max_width: int = 1024) -> np.ndarray:
    """(H', W', 3) uint8 sRGB picture of the window `image` (h, w, 3) linear radiance with the
    (h, w) bool `proxy` and `segmented` object marked; enlarged by the smallest whole factor
    that makes it `min_width` wide (or the largest within `max_width`), reduced by averaging
    blocks where it is wider than `max_width`."""
    picture = _tone_map(np.asarray(image, dtype=np.float32))
    proxy = np.asarray(proxy, dtype=bool)
    segmented = np.asarray(segmented, dtype=bool)
    w = picture.shape[1]
    if w > max_width:
        k = -(-w // max_width)
        picture = _reduce(picture, k)
        proxy, segmented = _reduce(proxy, k) >= 0.5, _reduce(segmented, k) >= 0.5
    else:
        k = max(1, min(-(-min_width // w), max_width // w))
        picture, proxy, segmented = (np.repeat(np.repeat(a, k, axis=0), k, axis=1) for a in (picture, proxy, segmented))
    picture = np.where((segmented & ~proxy)[..., None], (1 - _TINT) * picture + _TINT * _MISSED, picture)
    picture = np.where((proxy & ~segmented)[..., None], (1 - _TINT) * picture + _TINT * _EXCESS, picture)
    picture[outline(proxy)] = _PROXY_LINE
    picture[outline(segmented)] = _OBJECT_LINE
    return np.round(_srgb(picture) * 255.0).astype(np.uint8)


def _tone_map(rgb: np.ndarray) -> np.ndarray:
    """Linear display values in [0, 1): an exposure putting the 99th percentile of luminance at 1
    (half of white: a lamp above it no longer darkens the rest), then Reinhard's x / (1 + x) on
    luminance, which keeps a lamp's hue instead of clipping it to white."""
    luminance = np.maximum(rgb, 0.0) @ _LUMINANCE
    top = float(np.percentile(luminance, 99.0))
    exposure = 1.0 / top if top > 0.0 else 1.0
    y = luminance * exposure
    scale = np.where(y > 0.0, 1.0 / (1.0 + y), 0.0) * exposure
    return np.clip(np.maximum(rgb, 0.0) * scale[..., None], 0.0, 1.0).astype(np.float32)


def _srgb(linear: np.ndarray) -> np.ndarray:
    return np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.power(linear, 1.0 / 2.4) - 0.055)


def _reduce(a: np.ndarray, k: int) -> np.ndarray:
    """Means of k x k blocks, the last row and column repeated to fill the blocks at the edges."""
    a = np.asarray(a, dtype=np.float32)
    h, w = a.shape[:2]
    pad = [(0, -h % k), (0, -w % k)] + [(0, 0)] * (a.ndim - 2)
    a = np.pad(a, pad, mode="edge")
    return a.reshape(a.shape[0] // k, k, a.shape[1] // k, k, *a.shape[2:]).mean(axis=(1, 3))
