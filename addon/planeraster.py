"""Rectified rasters over a plane the removed object hid: where texture synthesis runs.

Texture statistics are stationary on the plane, not in the distorted panorama (thesis 4.2).
A raster is a square grid of cells over one plane, in the probe frame (the probe at the
origin); each cell has its 3D point, its lat-long position, and a flag: seen from the probe,
hidden by the removed object, or neither (off the surface, or hidden by something else).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import latlong

SEEN, HIDDEN, OTHER = 0, 1, 2


@dataclass
class PlaneRaster:
    """Cells (row i, column j) have centres origin + (j + 0.5) cell u + (i + 0.5) cell v."""

    origin: np.ndarray  # (3,) corner of the raster on the plane
    u: np.ndarray  # (3,) unit axis of the columns
    v: np.ndarray  # (3,) unit axis of the rows
    cell: float  # edge of a cell
    shape: tuple[int, int]

    def points(self) -> np.ndarray:
        """(h, w, 3) cell centres."""
        h, w = self.shape
        j = (np.arange(w) + 0.5) * self.cell
        i = (np.arange(h) + 0.5) * self.cell
        return self.origin + i[:, None, None] * self.v + j[None, :, None] * self.u

    def coords(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Continuous (row, column) of points on the plane, cell centres at integers."""
        rel = np.asarray(points, dtype=np.float64) - self.origin
        return rel @ self.v / self.cell - 0.5, rel @ self.u / self.cell - 0.5


def plane_axes(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit axes spanning the plane: on a floor or ceiling u follows x, on a wall u is
    horizontal, so tile lines along the room's axes run along the raster's rows or columns."""
    n = np.asarray(normal, dtype=np.float64) / np.linalg.norm(normal)
    a = np.array([1.0, 0.0, 0.0]) if abs(n[2]) > 0.9 else np.cross([0.0, 0.0, 1.0], n)
    u = a - (a @ n) * n
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def build_raster(normal: np.ndarray, hidden_points: np.ndarray, cell: float, margin: float,
                 max_cells: int) -> PlaneRaster:
    """A raster over the plane of `hidden_points` (N, 3) covering them and `margin` times their
    extent on every side (the exemplar around the hole); `cell` grows if the raster would
    exceed `max_cells` cells."""
    u, v = plane_axes(normal)
    pu, pv = hidden_points @ u, hidden_points @ v
    extent = max(float(np.ptp(pu)), float(np.ptp(pv)), cell)
    pad = margin * extent
    lo_u, hi_u = pu.min() - pad, pu.max() + pad
    lo_v, hi_v = pv.min() - pad, pv.max() + pad
    area = (hi_u - lo_u) * (hi_v - lo_v)
    cell = max(cell, float(np.sqrt(area / max_cells)))
    shape = (int(np.ceil((hi_v - lo_v) / cell)), int(np.ceil((hi_u - lo_u) / cell)))
    offset = float(np.mean(hidden_points @ (np.cross(u, v))))
    origin = lo_u * u + lo_v * v + offset * np.cross(u, v)
    return PlaneRaster(origin=origin, u=u, v=v, cell=cell, shape=shape)


def classify(raster: PlaneRaster, surface_with: np.ndarray, distance_with: np.ndarray,
             surface_without: np.ndarray, distance_without: np.ndarray, hidden_by_target: np.ndarray,
             surface: int, tolerance: float) -> np.ndarray:
    """(h, w) SEEN / HIDDEN / OTHER for each cell.

    The panorama maps are (H, W): the surface id each pixel's ray hits first and at what
    distance, with the object and without it, and whether the object is that first hit. A cell
    is on the surface where the ray through it, without the object, meets this surface at the
    cell's own distance (within `tolerance`, relative, plus a pixel's depth span)."""
    pts = raster.points()
    dist = np.linalg.norm(pts, axis=-1)
    u, v = latlong.direction_to_uv(pts)
    row, col = latlong.uv_to_pixel(u, v, surface_with.shape[1], surface_with.shape[0])

    # The pixel's own ray is up to half a pixel off the cell's: on a plane seen at a grazing
    # angle that moves its hit point along the ray by about dist * pixel angle / cos.
    cos = np.abs(pts @ np.cross(raster.u, raster.v)) / np.maximum(dist, 1e-300)
    slack = dist * (tolerance + np.pi / surface_with.shape[0] / np.maximum(cos, 0.05))

    def meets(surf: np.ndarray, d: np.ndarray) -> np.ndarray:
        return (surf[row, col] == surface) & (np.abs(d[row, col] - dist) <= slack)

    flags = np.full(raster.shape, OTHER, dtype=np.int8)
    flags[meets(surface_with, distance_with)] = SEEN
    flags[hidden_by_target[row, col] & meets(surface_without, distance_without)] = HIDDEN
    return flags


def sample_panorama(raster: PlaneRaster, image: np.ndarray, valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear lookup of a panorama image (H, W, C) at the cells, from `valid` pixels only:
    (h, w, C) values and (h, w) the weight the valid pixels had (0 where none)."""
    u, v = latlong.direction_to_uv(raster.points())
    stacked = np.concatenate([image * valid[..., None], valid[..., None].astype(np.float64)], axis=-1)
    s = latlong.sample_bilinear(stacked, u, v)
    weight = s[..., -1]
    values = s[..., :-1] / np.where(weight > 0.0, weight, 1.0)[..., None]
    return values, weight


def sample_raster(raster: PlaneRaster, image: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Bilinear lookup of a raster image (h, w, C) at points (N, 3) on its plane (clamped)."""
    h, w = raster.shape
    r, c = raster.coords(points)
    r = np.clip(r, 0.0, h - 1.0)
    c = np.clip(c, 0.0, w - 1.0)
    r0 = np.minimum(np.floor(r).astype(np.int64), max(h - 2, 0))
    c0 = np.minimum(np.floor(c).astype(np.int64), max(w - 2, 0))
    r1, c1 = np.minimum(r0 + 1, h - 1), np.minimum(c0 + 1, w - 1)
    fr, fc = (r - r0)[:, None], (c - c0)[:, None]
    top = image[r0, c0] * (1.0 - fc) + image[r0, c1] * fc
    bottom = image[r1, c0] * (1.0 - fc) + image[r1, c1] * fc
    return top * (1.0 - fr) + bottom * fr
