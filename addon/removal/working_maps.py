"""The working-resolution solution as maps over its panorama, and how a full-resolution pixel
finds its working neighbours and its own surface."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.candidates import CandidateHits, hits_among
from ..geometry.mesh import Geometry
from ..light.radiosity import LUMA
from .solution import Solution


@dataclass(frozen=True)
class WorkingMaps:
    """Per working pixel (flat, h*w): what the upsampling reads."""

    width: int
    height: int
    key: np.ndarray  # surface key of what it sees, -1 for nothing
    valid: np.ndarray  # bool: relit by the ratio form (seen, not hidden, not a light)
    emitter: np.ndarray  # bool: it sees a light source
    e: np.ndarray  # (h*w, 3) float32 E with the object (0 where not valid)
    de: np.ndarray  # (h*w, 3) float32 dE
    # (h*w, K) the distinct triangles its 3 x 3 neighbourhood sees without the object, in the
    # neighbourhood's order, then -1: what a full-resolution pixel nearest to it may see
    candidates: np.ndarray


def working_maps(solution: Solution) -> WorkingMaps:
    """The maps of a working-resolution solution."""
    traced = solution.traced
    n = traced.height * traced.width
    keys = solution.target.surface_key
    key = np.full(n, -1, dtype=np.int64)
    key[traced.hp] = keys[traced.tri_h]
    valid = np.zeros(n, dtype=bool)
    valid[traced.hp] = ~traced.hidden_h & ~solution.room.pixels.emitter_h
    emitter = np.zeros(n, dtype=bool)
    emitter[traced.hp] = solution.room.pixels.emitter_h
    e = np.zeros((n, 3), dtype=np.float32)
    de = np.zeros((n, 3), dtype=np.float32)
    e[traced.hp], de[traced.hp] = solution.e_h, solution.de_h
    return WorkingMaps(traced.width, traced.height, key, valid, emitter, e, de, _neighbourhood_triangles(
        traced.behind.tri_without, traced.height, traced.width))


def _neighbourhood_triangles(tri: np.ndarray, height: int, width: int) -> np.ndarray:
    """(h*w, K) the distinct triangles of `tri` (h*w,) in each pixel's 3 x 3 neighbourhood
    (wrapping around the seam, clamped at the poles), first ones first, -1 after them; K the
    most any neighbourhood holds. At a room's edges they are two or three of the nine: the
    full-resolution pixels there test those alone."""
    grid = tri.reshape(height, width)
    rows = np.arange(height)
    near = np.stack([np.roll(grid[np.clip(rows + dy, 0, height - 1)], -dx, axis=1).ravel()
                     for dy in (-1, 0, 1) for dx in (-1, 0, 1)], axis=1)
    repeat = near < 0
    for j in range(1, near.shape[1]):
        repeat[:, j] |= (near[:, :j] == near[:, j:j + 1]).any(axis=1)
    order = np.argsort(repeat, axis=1, kind="stable")
    distinct = np.take_along_axis(np.where(repeat, -1, near), order, axis=1)
    return distinct[:, :max(1, int((~repeat).sum(axis=1).max()))]


@dataclass(frozen=True)
class Cells:
    """The cells between working pixels that full-resolution pixels interpolate within: cell
    (k, j) spans working rows k-1 and k (clamped: row pair 0 and h repeat the first and last
    row) and columns j and j+1 (wrapping)."""

    plain: np.ndarray  # (h+1, w) bool: its four corners are relit and see one surface
    spread: np.ndarray  # (h+1, w) how much its corners' dE / E differ (on plain cells)

    @staticmethod
    def rows(maps: WorkingMaps) -> tuple[np.ndarray, np.ndarray]:
        """The working rows above and below each row pair."""
        k = np.arange(maps.height + 1)
        return np.clip(k - 1, 0, maps.height - 1), np.clip(k, 0, maps.height - 1)


def cells(maps: WorkingMaps) -> Cells:
    """The cells of the working maps."""
    top, bottom = Cells.rows(maps)
    shape = (maps.height, maps.width)
    key, valid = maps.key.reshape(shape), maps.valid.reshape(shape)
    ratio = ((maps.de @ LUMA) / np.maximum(maps.e @ LUMA, 1e-30)).reshape(shape)
    corners = [(rows, shift) for rows in (top, bottom) for shift in (0, -1)]
    keys = [np.roll(key[r], s, axis=1) for r, s in corners]
    plain = np.logical_and.reduce([np.roll(valid[r], s, axis=1) for r, s in corners]
                                  + [k == keys[0] for k in keys[1:]])
    ratios = np.stack([np.roll(ratio[r], s, axis=1) for r, s in corners])
    return Cells(plain, np.where(plain, np.ptp(ratios, axis=0), 0.0).astype(np.float32))


@dataclass(frozen=True)
class Neighbours:
    """For full-resolution pixels: the flat indices (4, N) of their four bilinear working
    neighbours and the weights (4, N)."""

    index: np.ndarray
    weight: np.ndarray


def _working_coordinates(rows: np.ndarray, cols: np.ndarray, full: tuple[int, int], maps: WorkingMaps
                         ) -> tuple[np.ndarray, np.ndarray]:
    """The continuous working row and column of full-resolution pixels (rows, cols) of a
    (height, width) panorama (0 at a working pixel's centre)."""
    height, width = full
    return (rows + 0.5) * (maps.height / height) - 0.5, (cols + 0.5) * (maps.width / width) - 0.5


def neighbours(rows: np.ndarray, cols: np.ndarray, full: tuple[int, int], maps: WorkingMaps) -> Neighbours:
    """The working neighbours of full-resolution pixels (rows, cols) of a (height, width)
    panorama; they wrap around the seam and clamp at the poles."""
    y, x = _working_coordinates(rows, cols, full, maps)
    y0, x0 = np.floor(y), np.floor(x)
    fy, fx = y - y0, x - x0
    ya = np.clip(y0.astype(np.int64), 0, maps.height - 1)
    yb = np.clip(y0.astype(np.int64) + 1, 0, maps.height - 1)
    xa = np.mod(x0.astype(np.int64), maps.width)
    xb = np.mod(x0.astype(np.int64) + 1, maps.width)
    index = np.stack([ya * maps.width + xa, ya * maps.width + xb, yb * maps.width + xa, yb * maps.width + xb])
    weight = np.stack([(1 - fy) * (1 - fx), (1 - fy) * fx, fy * (1 - fx), fy * fx])
    return Neighbours(index, weight)


def nearest_working(rows: np.ndarray, cols: np.ndarray, full: tuple[int, int], maps: WorkingMaps) -> np.ndarray:
    """The flat index of the working pixel nearest to each full-resolution pixel (rows, cols),
    which broadcast against each other (a block's rows down, its columns across)."""
    y, x = _working_coordinates(rows, cols, full, maps)
    ny = np.clip(np.round(y).astype(np.int64), 0, maps.height - 1)
    nx = np.mod(np.round(x).astype(np.int64), maps.width)
    return ny * maps.width + nx


def surfaces_seen(directions: np.ndarray, nearest: np.ndarray, geo: Geometry, maps: WorkingMaps) -> CandidateHits:
    """What full-resolution pixels see without the object, among the triangles their nearest
    working pixel's 3 x 3 neighbourhood sees without it."""
    candidates = maps.candidates[nearest]
    # Most pixels' neighbourhoods see one triangle: those test just it.
    uniform = candidates[:, 1] < 0 if candidates.shape[1] > 1 else np.ones(len(nearest), dtype=bool)
    if uniform.all() or not uniform.any():
        return hits_among(directions, geo.triangles, candidates[:, :1] if uniform.all() else candidates)
    one = hits_among(directions[uniform], geo.triangles, candidates[uniform, :1])
    many = hits_among(directions[~uniform], geo.triangles, candidates[~uniform])
    tri = np.empty(len(directions), dtype=np.int64)
    distance = np.empty(len(directions))
    bary = np.empty((len(directions), 2))
    for part, hits in ((uniform, one), (~uniform, many)):
        tri[part], distance[part], bary[part] = hits.tri, hits.distance, hits.bary
    return CandidateHits(tri, distance, bary)
