"""The equirectangular (lat-long) mapping of Blender's Environment Texture node.

A world direction d samples the texture at t = R d (R: the Mapping node's rotation, identity
without one), at u = 0.5 - atan2(t_y, t_x) / (2 pi), v = 1 - acos(t_z) / pi (Cycles'
`direction_to_equirectangular`): +X is the image centre, the seam is at -X, v = 1 is up.
Images here are (H, W, C) arrays with row 0 at the top (v = 1), as in an EXR file.
"""
from __future__ import annotations

import numpy as np


def direction_to_uv(d: np.ndarray, rotation: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Texture coordinates (u, v) in [0, 1] of world directions d (..., 3), any length."""
    d = np.asarray(d, dtype=np.float64)
    if rotation is not None:
        d = d @ np.asarray(rotation, dtype=np.float64).T
    n = np.linalg.norm(d, axis=-1)
    n = np.where(n > 0.0, n, 1.0)
    u = 0.5 - np.arctan2(d[..., 1], d[..., 0]) / (2.0 * np.pi)
    v = 1.0 - np.arccos(np.clip(d[..., 2] / n, -1.0, 1.0)) / np.pi
    return u, v


def uv_to_direction(u: np.ndarray, v: np.ndarray, rotation: np.ndarray | None = None) -> np.ndarray:
    """Unit world directions (..., 3) that sample the texture at (u, v)."""
    phi = (0.5 - np.asarray(u, dtype=np.float64)) * 2.0 * np.pi
    theta = (1.0 - np.asarray(v, dtype=np.float64)) * np.pi
    s = np.sin(theta)
    t = np.stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)], axis=-1)
    if rotation is not None:
        # R is a rotation, so its inverse is its transpose: d = R^T t.
        t = t @ np.asarray(rotation, dtype=np.float64)
    return t


def pixel_uv(width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) texture coordinates of pixel centres, row 0 at the top."""
    u = (np.arange(width) + 0.5) / width
    v = 1.0 - (np.arange(height) + 0.5) / height
    return np.broadcast_to(u[None, :], (height, width)), np.broadcast_to(v[:, None], (height, width))


def pixel_directions(width: int, height: int, rotation: np.ndarray | None = None) -> np.ndarray:
    """(H, W, 3) unit world directions through the pixel centres of a W x H panorama."""
    u, v = pixel_uv(width, height)
    return uv_to_direction(u, v, rotation)


def pixel_directions_at(rows: np.ndarray, cols: np.ndarray, width: int, height: int) -> np.ndarray:
    """(..., 3) unit directions through the centres of pixels (rows, cols) of a W x H panorama."""
    return uv_to_direction((np.asarray(cols) + 0.5) / width, 1.0 - (np.asarray(rows) + 0.5) / height)


def pixel_solid_angles(width: int, height: int) -> np.ndarray:
    """(H, 1) solid angle of one pixel in each row (exact for the row's latitude band)."""
    edges = np.pi * np.arange(height + 1) / height  # polar angle of row boundaries, top first
    band = np.cos(edges[:-1]) - np.cos(edges[1:])
    return (band * 2.0 * np.pi / width)[:, None]


def uv_to_pixel(u: np.ndarray, v: np.ndarray, width: int, height: int) -> tuple[np.ndarray, np.ndarray]:
    """Integer (row, column) of the texel containing (u, v)."""
    col = np.mod(np.floor(np.asarray(u) * width).astype(np.int64), width)
    row = np.clip(np.floor((1.0 - np.asarray(v)) * height).astype(np.int64), 0, height - 1)
    return row, col



def dilate(mask: np.ndarray, radius: int = 1) -> np.ndarray:
    """(H, W) bool mask grown by `radius` pixels (square): wraps around the u seam, clamps at
    the poles."""
    out = np.asarray(mask, dtype=bool)
    rows = out.copy()
    for k in range(1, min(radius, out.shape[0] - 1) + 1):
        rows[k:] |= out[:-k]
        rows[:-k] |= out[k:]
    out = rows.copy()
    for k in range(1, radius + 1):
        out |= np.roll(rows, k, axis=1) | np.roll(rows, -k, axis=1)
    return out
