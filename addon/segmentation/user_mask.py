"""The artist's mask: pixels added to or taken away from the region the removal fills.

Painted in Blender's Image Editor or any paint program over the panorama: white adds, black
takes away, mid grey or transparent leaves the computed region as it is. A black-and-white
mask therefore replaces the computed region outright. It is the panorama's size or an integer
fraction of it (a quarter-size mask of a 16K panorama paints and loads far faster).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DimredError
from ..geometry.planeraster import Frame

_ADD = 0.75  # grey value at and above which a pixel is added
_TAKE = 0.25  # ... at and below which it is taken away
_OPAQUE = 0.5  # alpha below which a pixel leaves the region as it is


@dataclass(frozen=True)
class UserMask:
    """(h, w) bool maps over the whole panorama at the mask's own size, row 0 at the top."""

    add: np.ndarray
    take: np.ndarray
    source: str

    def in_frame(self, frame: Frame, shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        """(add, take) over an (h, w) window `frame` of a panorama of another size: each
        window pixel reads the mask pixel holding its centre."""
        h, w = self.add.shape
        rows = np.minimum(((frame.row0 + np.arange(shape[0]) + 0.5) * (h / frame.height)).astype(np.int64), h - 1)
        cols = np.mod(frame.col0 + np.arange(shape[1]), frame.width)
        cols = np.minimum(((cols + 0.5) * (w / frame.width)).astype(np.int64), w - 1)
        return self.add[rows][:, cols], self.take[rows][:, cols]


def user_mask(pixels: np.ndarray, *, panorama: tuple[int, int], source: str) -> UserMask:
    """The mask of (h, w) or (h, w, C) pixels in [0, 1] (C: grey, grey+alpha, RGB or RGBA; row
    0 at the top) for a panorama of `panorama` = (width, height); DimredError, naming
    `source`, when it is no image or not the panorama's size or an integer fraction of it."""
    a = np.asarray(pixels)
    if a.ndim == 2:
        a = a[..., None]
    if a.ndim != 3 or a.shape[2] not in (1, 2, 3, 4) or min(a.shape[:2]) < 1 or not np.issubdtype(a.dtype, np.number):
        raise DimredError(f"the mask {source} is not an image (got an array of shape {np.shape(pixels)})")
    h, w = a.shape[:2]
    width, height = panorama
    if width % w or height % h or width // w != height // h:
        raise DimredError(f"the mask {source} is {w}x{h} but the panorama is {width}x{height}: paint it at the "
                          "panorama's size or an integer fraction of it")
    a = a.astype(np.float32, copy=False)
    if not np.isfinite(a).all():
        raise DimredError(f"the mask {source} holds NaN or infinite values")
    colour = a[..., :3] if a.shape[2] >= 3 else a[..., :1]
    grey = colour.mean(axis=2)
    opaque = a[..., -1] >= _OPAQUE if a.shape[2] in (2, 4) else np.ones((h, w), dtype=bool)
    return UserMask(add=opaque & (grey >= _ADD), take=opaque & (grey <= _TAKE), source=source)
