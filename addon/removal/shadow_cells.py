"""The object's shadows of the important senders at panorama pixels, computed exactly at the
corners of square cells of pixels and interpolated inside a cell where its corners agree.

A large emitter (a window, a lit wall) shadows much of the room softly: its object shadow is
significant at most pixels but changes slowly from pixel to pixel, so computing every pixel's
pairs costs what the window's area costs, not what the shadow's detail needs. A cell's corners
get the exact shadow of every sender significant anywhere in the cell; where the spread of
those corner values, summed over the senders, stays under the budget of each corner (a share
of its light), or where the mix of the corners gets the cell's middle pixel right to within
it (a gradient, as in a window's broad penumbra), every pixel of the cell on the corners'
plane takes the bilinear mix of them. Elsewhere (the shadow's sharp edge, the object's
outline, a change of surface, a corner hidden behind the object) each pixel gets its own. As
the exact values inside a smooth cell lie between its corners' or follow their gradient, the
spread or the middle's miss bounds what the mix gets wrong; a feature of the object narrower
than a cell whose shadow passes between its corners and its middle breaks that, so the cell
is kept to a few pixels, narrower than the legs of the furniture it meets.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..light.radiosity import LUMA

_SAME_PLANE_COS = 0.999  # corners whose normal turns further are on another surface
_SAME_PLANE_GAP = 1e-3  # ... or that lie further off the pixel's plane, as a share of its distance

#: The exact shadow of pairs (receiving rows (n,), senders (n,)): what it adds to E and to dE,
#: each (n, 3).
PairShadow = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


@dataclass(frozen=True)
class PixelGrid:
    """Where the receiving points lie in the panorama: the flat index (N,) of each point's
    pixel in a `height` x `width` image."""

    flat: np.ndarray
    height: int
    width: int


@dataclass(frozen=True)
class CellShadows:
    """What the shadows add to E and dE at every receiving point (N, 3), the points that took
    them from their cell's corners, and the (point, sender) pairs computed exactly (at the
    corners and at the other points)."""

    e: np.ndarray
    de: np.ndarray
    interpolated_points: int
    computed_pairs: int


def cell_shadows(points: np.ndarray, normals: np.ndarray, usable: np.ndarray, grid: PixelGrid | None,
                 rows: np.ndarray, senders: np.ndarray, budget: np.ndarray, shadow: PairShadow, *,
                 cell: int) -> CellShadows:
    """The shadows of the significant pairs (receiving rows `rows`, senders `senders`): at the
    points with pairs, exact or from their cells of `cell` pixels on `grid` (None, or a cell of
    1: all exact). Corners must be `usable` (N,) rows; `budget` (N,) is the luminance a
    corner's interpolation may get wrong."""
    n = len(points)
    e, de = np.zeros((n, 3)), np.zeros((n, 3))
    interpolated = np.zeros(n, dtype=bool)
    computed = 0
    if grid is not None and cell > 1 and len(rows):
        served, corner_e, corner_de, corner_pairs = _smooth_cells(points, normals, usable, grid, rows, senders,
                                                                  budget, shadow, cell)
        computed += corner_pairs
        e[served.rows] = np.einsum("nk,nkc->nc", served.weights, corner_e[served.cell])
        de[served.rows] = np.einsum("nk,nkc->nc", served.weights, corner_de[served.cell])
        interpolated[served.rows] = True
    # A cell whose corners disagree is not split further: what made them disagree (the shadow
    # of a chair's leg, a few pixels wide) would pass between the corners of smaller cells.
    own = ~interpolated[rows]
    add_e, add_de = shadow(rows[own], senders[own])
    e += _sum_rows(rows[own], add_e, n)
    de += _sum_rows(rows[own], add_de, n)
    return CellShadows(e, de, int(interpolated.sum()), computed + int(own.sum()))


@dataclass(frozen=True)
class _Served:
    """Points served by a smooth cell: their rows (m,), cells (m,) and corner weights (m, 4)."""

    rows: np.ndarray
    cell: np.ndarray
    weights: np.ndarray


def _smooth_cells(points: np.ndarray, normals: np.ndarray, usable: np.ndarray, grid: PixelGrid, rows: np.ndarray,
                  senders: np.ndarray, budget: np.ndarray, shadow: PairShadow, cell: int
                  ) -> tuple[_Served, np.ndarray, np.ndarray, int]:
    """The points served by cells whose corners agree, or whose middle the corners' mix gets
    right, the summed shadow (C, 4, 3) at each cell's corners for E and for dE, and the pairs
    computed at corners and middles."""
    row_of = np.full(grid.height * grid.width, -1)
    row_of[grid.flat] = np.arange(len(grid.flat))
    r, c = np.divmod(grid.flat, grid.width)
    cols = -(-grid.width // cell)
    key = (r // cell) * cols + c // cell  # (N,) each point's cell
    # Which senders are significant somewhere in each cell, on a table of every cell: sorting
    # the millions of pairs of a window-lit room would cost more than the rest.
    present = np.flatnonzero(np.bincount(senders))
    column = np.zeros(present[-1] + 1, dtype=np.int64)
    column[present] = np.arange(len(present))
    table = np.zeros((-(-grid.height // cell) * cols, len(present)), dtype=bool)
    table[key[rows], column[senders]] = True
    cells = np.flatnonzero(table.any(axis=1))
    # The cell's corner pixels, wrapping around in longitude; the cells of the last row close
    # on the panorama's last row (their span is shorter), and one of a single row has none.
    r0, c0 = (cells // cols) * cell, (cells % cols) * cell
    r1, c1 = np.minimum(r0 + cell, grid.height - 1), (c0 + cell) % grid.width
    span = r1 - r0
    corner = row_of[np.stack([r0 * grid.width + c0, r0 * grid.width + c1, r1 * grid.width + c0,
                              r1 * grid.width + c1], axis=1)]
    ok = (span > 0) & (corner >= 0).all(axis=1)
    corner = np.where(ok[:, None], corner, 0)
    ok &= usable[corner].all(axis=1)

    # Every sender significant somewhere in a cell is taken at all four of its corners.
    pair_cell, pair_column = np.nonzero(table[cells[ok]])
    pair_cell = np.flatnonzero(ok)[pair_cell]
    at = corner[pair_cell]  # (m, 4)
    unique, inverse = np.unique(at * len(present) + pair_column[:, None], return_inverse=True)
    u_e, u_de = shadow(unique // len(present), present[unique % len(present)])
    inverse = inverse.reshape(-1, 4)
    spread = np.maximum(np.ptp(u_e[inverse] @ LUMA, axis=1), np.ptp(u_de[inverse] @ LUMA, axis=1))
    allowed = budget[corner].min(axis=1)
    smooth = ok & (np.bincount(pair_cell, spread, minlength=len(cells)) <= allowed)
    # Corners that differ more may still hold a gradient, which the mix follows: the cell's
    # middle pixel tells it from a shadow's edge or a bend, where the mix misses the middle.
    middle = row_of[np.minimum(r0 + cell // 2, grid.height - 1) * grid.width + (c0 + cell // 2) % grid.width]
    ask = ok & ~smooth & (middle >= 0)
    ask[ask] = usable[middle[ask]] & _on_plane(points, normals, middle[ask], corner[ask]).all(axis=1)
    asked = ask[pair_cell]
    m_e, m_de = shadow(middle[pair_cell[asked]], present[pair_column[asked]])
    # the middle pixel's place in its cell, along each axis
    mix = _bilinear(np.minimum(cell // 2, span) / np.maximum(span, 1), np.array((cell // 2) / cell))
    at_middle = mix[pair_cell[asked]]
    missed_e = _sum_rows(pair_cell[asked], np.einsum("nk,nkc->nc", at_middle, u_e[inverse[asked]]) - m_e,
                         len(cells)) @ LUMA
    missed_de = _sum_rows(pair_cell[asked], np.einsum("nk,nkc->nc", at_middle, u_de[inverse[asked]]) - m_de,
                          len(cells)) @ LUMA
    smooth |= ask & (np.maximum(np.abs(missed_e), np.abs(missed_de)) <= allowed)
    corner_e, corner_de = np.zeros((len(cells), 4, 3)), np.zeros((len(cells), 4, 3))
    for k in range(4):
        corner_e[:, k] = _sum_rows(pair_cell, u_e[inverse[:, k]], len(cells))
        corner_de[:, k] = _sum_rows(pair_cell, u_de[inverse[:, k]], len(cells))

    # The points with pairs in smooth cells take the corners on their own surface: in a cell
    # across a wall's edge, whose corners agree, each side mixes its own; the corners of a
    # cell taken for its gradient all lie on the middle's plane, and a point off it has none.
    with_pairs = np.zeros(len(points), dtype=bool)
    with_pairs[rows] = True  # as np.unique(rows), without sorting a window's millions of pairs
    p = np.flatnonzero(with_pairs)
    p_cell = np.searchsorted(cells, key[p])
    p, p_cell = p[smooth[p_cell]], p_cell[smooth[p_cell]]
    own = _on_plane(points, normals, p, corner[p_cell])
    weights = own * _bilinear((r[p] - r0[p_cell]) / span[p_cell], ((c[p] - c0[p_cell]) % grid.width) / cell)
    total = weights.sum(axis=1)
    served = own.any(axis=1) & (total > 0)
    weights = weights[served] / total[served, None]
    return _Served(p[served], p_cell[served], weights), corner_e, corner_de, len(unique) + int(asked.sum())


def _bilinear(fr: np.ndarray, fc: np.ndarray) -> np.ndarray:
    """(..., 4) the weights of a cell's corners (top left, top right, bottom left, bottom right)
    at the place (fr, fc) in it, each a share of the cell's side."""
    return np.stack([(1 - fr) * (1 - fc), (1 - fr) * fc, fr * (1 - fc), fr * fc], axis=-1)


def _on_plane(points: np.ndarray, normals: np.ndarray, p: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(n, 4) whether points p (n,) lie on the plane of each of their corners (n, 4): same
    normal, and off each other's plane by a hair of their distance from the probe."""
    facing = np.einsum("nc,nkc->nk", normals[p], normals[corners]) >= _SAME_PLANE_COS
    off = np.abs(np.einsum("nc,nkc->nk", normals[p], points[corners] - points[p][:, None, :]))
    return facing & (off <= _SAME_PLANE_GAP * np.linalg.norm(points[p], axis=1)[:, None])


def _sum_rows(rows: np.ndarray, values: np.ndarray, n: int) -> np.ndarray:
    """(n, C): values (k, C) summed into their rows."""
    return np.stack([np.bincount(rows, values[:, c], minlength=n) for c in range(values.shape[1])], axis=1)
