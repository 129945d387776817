"""Rectified rasters over a plane the removed object hid: where texture synthesis runs.

Texture statistics are stationary on the plane, not in the distorted panorama (thesis 4.2).
A raster is a square grid of cells over one plane, in the probe frame (the probe at the
origin); each cell has its 3D point, its lat-long position, and a flag: seen from the probe,
hidden by the removed object, or neither (off the surface, or hidden by something else).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..side_by_side import each
from . import latlong

SEEN, HIDDEN, OTHER = 0, 1, 2
_GRAIN_POINTS = 1 << 15  # points looked up at a time by sample_points_keeping_grain


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


# A plane whose normal lies within about 25 degrees of the horizontal is a wall: its raster's rows
# run upward (`plane_axes`), the fill continues its columns and its edges are no floor line.
_WALL_NORMAL_Z = 0.9


def is_wall(normal: np.ndarray) -> bool:
    """Whether the plane of `normal` (3,) is a wall: its raster's axis 0 (v) is vertical."""
    n = np.asarray(normal, dtype=np.float64)
    return abs(float(n[2])) <= _WALL_NORMAL_Z * float(np.linalg.norm(n))


def plane_axes(normal: np.ndarray, along: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Two unit axes spanning the plane. On a wall u is horizontal; on a floor or ceiling u
    follows `along` (the surface's own edges, see `edge_direction`), else the frame's x, so that
    tile and plank lines along the room's walls run along the raster's rows or columns."""
    n = np.asarray(normal, dtype=np.float64) / np.linalg.norm(normal)
    if not is_wall(n):
        a = np.array([1.0, 0.0, 0.0]) if along is None else np.asarray(along, dtype=np.float64)
    else:
        a = np.cross([0.0, 0.0, 1.0], n)
    u = a - (a @ n) * n
    u /= np.linalg.norm(u)
    return u, np.cross(n, u)


def edge_direction(triangles: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """(3,) the dominant direction, modulo a right angle, of the edges of a planar surface's
    triangles (T, 3, 3): the orientation (1-degree bins) that most edge length shares, refined
    over the edges within a degree of it. A floor's outline runs along the room's walls even
    when the frame (a rotated world) does not, and its quads' diagonals lose the vote."""
    e1, e2 = plane_axes(normal)
    edges = (np.roll(triangles, -1, axis=1) - triangles).reshape(-1, 3)
    x, y = edges @ e1, edges @ e2
    length = np.hypot(x, y)
    folded = np.mod(np.degrees(np.arctan2(y, x)), 90.0)  # edges at right angles share a value
    votes = np.bincount(np.minimum(folded.astype(np.int64), 89), weights=length, minlength=90)
    # Each bin with its neighbours (circularly): edges at 19.99 and 20.01 degrees vote together.
    votes = votes + np.roll(votes, 1) + np.roll(votes, -1)
    peak = float(np.argmax(votes)) + 0.5
    offset = (folded - peak + 45.0) % 90.0 - 45.0
    near = np.abs(offset) <= 1.5
    angle = np.radians(peak + (np.average(offset[near], weights=length[near]) if length[near].sum() > 0 else 0.0))
    return np.cos(angle) * e1 + np.sin(angle) * e2


def build_raster(normal: np.ndarray, hidden_points: np.ndarray, *, cell: float, margin: float,
                 max_cells: int, along: np.ndarray | None = None) -> PlaneRaster:
    """A raster over the plane of `hidden_points` (N, 3) covering them and `margin` times their
    extent on every side (the exemplar around the hole), its axes as `plane_axes(normal, along)`;
    `cell` grows if the raster would exceed `max_cells` cells."""
    u, v = plane_axes(normal, along)
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


@dataclass(frozen=True)
class Frame:
    """Where an (h, w) array of panorama pixels lies in the full W x H panorama: its first row
    and first column (its columns wrap around the seam). The whole panorama is (0, 0, H, W)."""

    row0: int
    col0: int
    height: int
    width: int

    @classmethod
    def whole(cls, shape: tuple[int, ...]) -> Frame:
        return cls(0, 0, shape[0], shape[1])

    def locate(self, rows: np.ndarray, cols: np.ndarray, shape: tuple[int, ...]
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Panorama (row, column) pixels -> the array's (row, column) and whether it holds them."""
        r = rows - self.row0
        c = np.mod(cols - self.col0, self.width)
        inside = (r >= 0) & (r < shape[0]) & (c < shape[1])
        return np.clip(r, 0, shape[0] - 1), np.minimum(c, shape[1] - 1), inside


def classify(raster: PlaneRaster, surface_with: np.ndarray, distance_with: np.ndarray,
             surface_without: np.ndarray, distance_without: np.ndarray, hidden_by_target: np.ndarray,
             *, surface: int, tolerance: float, frame: Frame | None = None) -> np.ndarray:
    """(h, w) SEEN / HIDDEN / OTHER for each cell.

    The panorama maps hold the pixels of `frame` (default: the whole panorama): the surface id
    each pixel's ray hits first and at what distance, with the object and without it, and
    whether the object is that first hit. A cell is on the surface where the ray through it,
    without the object, meets this surface at the cell's own distance (within `tolerance`,
    relative, plus a pixel's depth span); cells outside the frame are OTHER."""
    frame = frame or Frame.whole(surface_with.shape)
    pts = raster.points()
    dist = np.linalg.norm(pts, axis=-1)
    u, v = latlong.direction_to_uv(pts)
    row, col, inside = frame.locate(*latlong.uv_to_pixel(u, v, frame.width, frame.height), surface_with.shape)

    # The pixel's own ray is up to half a pixel off the cell's: on a plane seen at a grazing
    # angle that moves its hit point along the ray by about dist * pixel angle / cos.
    cos = np.abs(pts @ np.cross(raster.u, raster.v)) / np.maximum(dist, 1e-300)
    slack = dist * (tolerance + np.pi / frame.height / np.maximum(cos, 0.05))

    def meets(surf: np.ndarray, d: np.ndarray) -> np.ndarray:
        return inside & (surf[row, col] == surface) & (np.abs(d[row, col] - dist) <= slack)

    flags = np.full(raster.shape, OTHER, dtype=np.int8)
    flags[meets(surface_with, distance_with)] = SEEN
    flags[hidden_by_target[row, col] & meets(surface_without, distance_without)] = HIDDEN
    return flags


def sample_panorama(raster: PlaneRaster, image: np.ndarray, valid: np.ndarray, *, frame: Frame | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear lookup of panorama pixels (h, w, C) covering `frame` (default: the whole
    panorama) at the cells, from `valid` pixels only: (h, w, C) values and (h, w) the weight
    the valid pixels had (0 where none)."""
    return sample_points(raster.points(), image, valid, frame=frame)


def sample_points(points: np.ndarray, image: np.ndarray, valid: np.ndarray, *, frame: Frame | None = None
                  ) -> tuple[np.ndarray, np.ndarray]:
    """`sample_panorama` at any points (..., 3) in the probe frame: (..., C) and (...)."""
    frame = frame or Frame.whole(image.shape)
    y0, x0, fy, fx = _lookup_position(points, frame)
    total, weight = 0.0, 0.0
    for dy, dx, w in _bilinear_weights(fy, fx):
        r, c, inside = frame.locate(np.minimum(y0 + dy, frame.height - 1), x0 + dx, valid.shape)
        w = w * (inside & valid[r, c])
        total = total + w[..., None] * image[r, c]
        weight = weight + w
    return total / np.where(weight > 0.0, weight, 1.0)[..., None], weight


def sample_points_keeping_grain(points: np.ndarray, image: np.ndarray, valid: np.ndarray, *,
                                frame: Frame | None = None) -> tuple[np.ndarray, np.ndarray]:
    """`sample_points` whose deviations from the local mean (of the valid pixels in the 3 x 3
    around each pixel looked up) keep the spread of a single pixel. A bilinear lookup between
    pixels averages up to four of them: their independent grain (sensor or render noise, the
    finest texture) shrinks to as little as half its spread, and a copy of the photograph looks
    softer than the photograph around it. Variance-preserving blending (Heitz and Neyret 2018)
    divides the weighted deviations by the root of the summed squared weights, which gives
    i.i.d. grain its own spread back while a smooth signal, equal to its local mean, is
    interpolated as before."""
    frame = frame or Frame.whole(image.shape)
    flat = points.reshape(-1, 3)
    # In chunks, side by side: the sixteen lookups and their sums over a chunk stay in a core's
    # cache (250k points at 8K: 0.40 s at once, 0.20 s so).
    parts = each(lambda start: _keeping_grain(flat[start:start + _GRAIN_POINTS], image, valid, frame),
                 range(0, len(flat), _GRAIN_POINTS))
    if not parts:
        return np.zeros((*points.shape[:-1], image.shape[-1])), np.zeros(points.shape[:-1])
    return (np.concatenate([p[0] for p in parts]).reshape(*points.shape[:-1], -1),
            np.concatenate([p[1] for p in parts]).reshape(points.shape[:-1]))


def _keeping_grain(points: np.ndarray, image: np.ndarray, valid: np.ndarray, frame: Frame
                   ) -> tuple[np.ndarray, np.ndarray]:
    """`sample_points_keeping_grain` at (N, 3) points."""
    y0, x0, fy, fx = _lookup_position(points, frame)
    # the 4 x 4 pixels around each point: its four taps and their 3 x 3 neighbourhoods
    value, known = {}, {}
    for oy in range(-1, 3):
        for ox in range(-1, 3):
            r, c, inside = frame.locate(y0 + oy, x0 + ox, valid.shape)  # rows past the poles are outside
            known[oy, ox] = inside & valid[r, c]
            value[oy, ox] = np.where(known[oy, ox][..., None], image[r, c], 0.0)
    total, mean, weight, square = 0.0, 0.0, 0.0, 0.0
    for dy, dx, w in _bilinear_weights(fy, fx):
        # (past the last row a tap is invalid here, where `sample_points` repeats the row: the
        # point lies on the last row then, and that tap's weight is 0 either way)
        near = [(dy + a, dx + b) for a in (-1, 0, 1) for b in (-1, 0, 1)]
        count = sum(known[k].astype(np.float64) for k in near)
        local = sum(value[k] for k in near) / np.maximum(count, 1)[..., None]
        w = w * known[dy, dx]
        total = total + w[..., None] * value[dy, dx]
        mean = mean + w[..., None] * local
        weight = weight + w
        square = square + w * w
    norm = np.where(weight > 0.0, weight, 1.0)[..., None]
    gain = (weight / np.sqrt(np.where(square > 0.0, square, 1.0)))[..., None]
    return (mean + gain * (total - mean)) / norm, weight


def _bilinear_weights(fy: np.ndarray, fx: np.ndarray) -> list[tuple[int, int, np.ndarray]]:
    """(row step, column step, weight) of the four taps at fractional offsets (fy, fx)."""
    return [(dy, dx, wy * wx) for dy, wy in ((0, 1.0 - fy), (1, fy)) for dx, wx in ((0, 1.0 - fx), (1, fx))]


def _lookup_position(points: np.ndarray, frame: Frame) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The panorama pixel (row, column) left of and above each point (..., 3), and the point's
    fractional offset from it (rows, columns)."""
    u, v = latlong.direction_to_uv(points)
    x = u * frame.width - 0.5
    y = np.clip((1.0 - v) * frame.height - 0.5, 0.0, frame.height - 1.0)  # clamped at the poles
    x0, y0 = np.floor(x), np.floor(y)
    return y0.astype(np.int64), x0.astype(np.int64), y - y0, x - x0


def sample_raster(raster: PlaneRaster, image: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Bilinear lookup of a raster image (h, w, C) at points (N, 3) on its plane (clamped)."""
    h, w = raster.shape
    row, col = raster.coords(points)
    row = np.clip(row, 0.0, h - 1.0)
    col = np.clip(col, 0.0, w - 1.0)
    r0 = np.minimum(np.floor(row).astype(np.int64), max(h - 2, 0))
    c0 = np.minimum(np.floor(col).astype(np.int64), max(w - 2, 0))
    r1, c1 = np.minimum(r0 + 1, h - 1), np.minimum(c0 + 1, w - 1)
    row_frac, col_frac = (row - r0)[:, None], (col - c0)[:, None]
    top = image[r0, c0] * (1.0 - col_frac) + image[r0, c1] * col_frac
    bottom = image[r1, c0] * (1.0 - col_frac) + image[r1, c1] * col_frac
    return top * (1.0 - row_frac) + bottom * row_frac
