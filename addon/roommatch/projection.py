"""Clicks as pixel coordinates of a W x H lat-long panorama, and the directions they stand for.

A click is (x, y) = (column, row) with row 0 at the top and whole numbers at pixel centres, so a
click on pixel (row r, column c) is (c, r) and looks along `latlong.pixel_directions_at(r, c)`.
Fractions are allowed; x runs over [-0.5, W - 0.5), y over [-0.5, H - 0.5].
"""
from __future__ import annotations

import numpy as np

from ..geometry import latlong


def click_directions(points: np.ndarray, width: int, height: int,
                     rotation: np.ndarray | None = None) -> np.ndarray:
    """(..., 3) unit world directions of the clicks `points` (..., 2) = (x, y)."""
    p = np.asarray(points, dtype=np.float64)
    return latlong.uv_to_direction((p[..., 0] + 0.5) / width, 1.0 - (p[..., 1] + 0.5) / height, rotation)


def project(points: np.ndarray, width: int, height: int, rotation: np.ndarray | None = None) -> np.ndarray:
    """(..., 2) click coordinates (x, y) where directions `points` (..., 3) from the probe land."""
    u, v = latlong.direction_to_uv(points, rotation)
    x = np.mod(u * width - 0.5 + 0.5, width) - 0.5  # the seam's column wraps to the left end
    return np.stack([x, (1.0 - v) * height - 0.5], axis=-1)


def pixel_offsets(a: np.ndarray, b: np.ndarray, width: int) -> np.ndarray:
    """(..., 2) a - b in pixels, the column difference taken the short way round the seam."""
    d = np.asarray(a, dtype=np.float64) - np.asarray(b, dtype=np.float64)
    d[..., 0] = np.mod(d[..., 0] + width / 2.0, width) - width / 2.0
    return d
