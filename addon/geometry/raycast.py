"""Vectorised ray casting: what each panorama pixel sees, and the hits of a few rays.

`trace_panorama` rasterises every triangle into the lat-long image as seen from the probe
(the origin of the probe frame) with a depth buffer: a ray from the probe is a pixel, so this
is exact first-hit ray casting without a loop over pixels. `first_hits` and `crossings` test
a few rays against every triangle. Which segments are blocked is `occluders.Occluders`.
"""
from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np

from ..side_by_side import each
from . import latlong

_BATCH_PIXELS = 1 << 20  # pixel tests at a time
_WIDE = 4096  # a triangle's window of this many pixels is tested alone
_MARGIN = 1e-3  # pixels a window reaches past a triangle's exact bounds (rounding)
_PAIR_CHUNK = 40_000
_PROJECT_TRIANGLES = 1 << 15  # triangles projected at a time


@dataclass
class PanoramaHits:
    """First hit of every pixel's ray from the probe; tri = -1 where nothing is hit."""

    tri: np.ndarray  # (H, W) int64
    distance: np.ndarray  # (H, W) float64, along the unit direction
    bary: np.ndarray  # (H, W, 2) barycentric weights of vertices 1 and 2
    directions: np.ndarray  # (H, W, 3) unit directions in the probe frame

    @property
    def points(self) -> np.ndarray:
        return self.directions * self.distance[..., None]


@dataclass(frozen=True)
class Projection:
    """Triangles as the origin sees them, whatever the panorama's size: what `trace_panorama`
    needs of each triangle before it rasterises it. A mesh is traced several times (its
    coarse spot, its segmentation window, the working copy, the full-resolution window):
    with 200k triangles, working this out took half of each trace. Rows and columns are
    shares of the panorama's height and width."""

    seen: np.ndarray  # (T,) bool: not edge-on (an edge-on triangle covers no pixel centre)
    edge_normals: np.ndarray  # (T, 3, 3) `_edge_normals`, zero where not seen
    normal: np.ndarray  # (T, 3) unnormalised normals ...
    offset: np.ndarray  # (T,) ... and their dot products with the first corner
    top: np.ndarray  # (T,) the least and greatest row share of any point of the triangle
    bottom: np.ndarray
    start: np.ndarray  # (T,) the column share where its run of longitudes starts ...
    span: np.ndarray  # ... and the run's length: the circle less the widest gap between corners
    north: np.ndarray  # (T,) bool: it holds the north pole, so every column near it
    south: np.ndarray

    def take(self, index: np.ndarray) -> Projection:
        """The projection of the triangles `index` (indices or a mask) picks, in that order."""
        return Projection(*(getattr(self, f.name)[index] for f in fields(self)))


def project(triangles: np.ndarray) -> Projection:
    """The `Projection` of triangles (T, 3, 3) seen from the origin.

    The bounds are exact: an edge seen from the origin is an arc of a great circle, shorter
    than half of it, along which the elevation has at most one extreme (`_edge_extreme_rows`)
    and the longitude runs one way, over less than half the circle. So a triangle that holds
    no pole spans the longitudes between its corners, the circle less the largest gap between
    them, and a few corners cost what a sliver of a pixel does."""
    # In chunks side by side: a chunk's (T, 3, 3) temporaries stay in a core's cache (a mesh of
    # 200k triangles: 0.31 s at once, 0.13 s so).
    parts = each(lambda start: _projected(triangles[start:start + _PROJECT_TRIANGLES]),
                 range(0, max(len(triangles), 1), _PROJECT_TRIANGLES))
    return Projection(*(np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(Projection)))


def _projected(triangles: np.ndarray) -> Projection:
    """`project` of the triangles (T, 3, 3) at once."""
    n = len(triangles)
    det = np.einsum("ij,ij->i", triangles[:, 0], np.cross(triangles[:, 1], triangles[:, 2]))
    scale = np.linalg.norm(triangles, axis=2).max(axis=1) ** 3
    seen = np.abs(det) > 1e-12 * scale
    tris = triangles[seen]
    edge_normals = np.zeros((n, 3, 3))
    edge_normals[seen] = _edge_normals(tris)
    corners = np.arccos(np.clip(tris[..., 2] / np.maximum(np.linalg.norm(tris, axis=2), 1e-300), -1.0, 1.0))
    rows = np.concatenate([corners / np.pi, _edge_extreme_rows(tris)], axis=1)
    u = np.sort(latlong.direction_to_uv(tris)[0], axis=1)
    gaps = np.diff(np.concatenate([u, u[:, :1] + 1.0], axis=1), axis=1)
    widest = gaps.argmax(axis=1)
    bounds = np.zeros((4, n))
    bounds[:, seen] = rows.min(axis=1), rows.max(axis=1), u[np.arange(len(u)), (widest + 1) % 3], 1.0 - gaps.max(axis=1)
    north, south = (edge_normals[..., 2] >= 0.0).all(axis=1) & seen, (edge_normals[..., 2] <= 0.0).all(axis=1) & seen
    normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    return Projection(seen, edge_normals, normal, np.einsum("tc,tc->t", normal, triangles[:, 0]), *bounds, north,
                      south)


def _uv_window(p: Projection, width: int, height: int) -> tuple[np.ndarray, ...]:
    """Pixel windows (row0, rows, col0, cols) holding the centres of every pixel that the
    triangles of the projection `p` may cover, widened by `_MARGIN` pixel; rows or cols 0
    where they cover none."""
    # Pixel r's centre lies at r + 0.5 rows (columns) from the top (the seam).
    row0 = np.maximum(np.ceil(p.top * height - 0.5 - _MARGIN), 0).astype(np.int64)
    row1 = np.minimum(np.floor(p.bottom * height - 0.5 + _MARGIN), height - 1).astype(np.int64)
    start = p.start * width
    col0 = np.ceil(start - 0.5 - _MARGIN).astype(np.int64)
    cols = np.floor(start + p.span * width - 0.5 + _MARGIN).astype(np.int64) - col0 + 1
    # A triangle around a pole covers every column near that pole.
    row0, row1 = np.where(p.north, 0, row0), np.where(p.south, height - 1, row1)
    col0, cols = np.where(p.north | p.south, 0, col0), np.where(p.north | p.south, width, cols)
    return row0, np.maximum(row1 - row0 + 1, 0), np.mod(col0, width), np.clip(cols, 0, width)


def _edge_extreme_rows(tris: np.ndarray) -> np.ndarray:
    """(T, 3) the row share (polar angle / pi) of each edge's interior extreme of elevation.

    Along p(t) = a + t (b - a) the elevation z / |p| has one stationary point, where
    t = (a_z a.e - e_z |a|^2) / (e_z a.e - a_z |e|^2); clipped to the edge, it is an endpoint
    when the extreme lies outside."""
    a = tris
    e = np.roll(tris, -1, axis=1) - tris
    ae = np.einsum("tkc,tkc->tk", a, e)
    aa = np.einsum("tkc,tkc->tk", a, a)
    ee = np.einsum("tkc,tkc->tk", e, e)
    num = a[..., 2] * ae - e[..., 2] * aa
    den = e[..., 2] * ae - a[..., 2] * ee
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(np.abs(den) > 0.0, num / den, 0.0)
    p = a + np.clip(np.nan_to_num(t), 0.0, 1.0)[..., None] * e
    z = p[..., 2] / np.maximum(np.linalg.norm(p, axis=2), 1e-300)
    return np.arccos(np.clip(z, -1.0, 1.0)) / np.pi


def _edge_normals(tris: np.ndarray) -> np.ndarray:
    """(T, 3, 3) normals of the planes through the origin and each edge, pointing inward."""
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    normals = np.stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)], axis=1)
    sign = np.sign(np.einsum("ij,ij->i", a, np.cross(b, c)))
    return normals * sign[:, None, None]


@dataclass(frozen=True)
class _Windows:
    """Rectangles of panorama pixels to test against one triangle each, in the order ties of
    depth go to (the first): `tri` (P,) indexes the triangles, the rest as `_uv_window`'s."""

    tri: np.ndarray
    row0: np.ndarray
    rows: np.ndarray
    col0: np.ndarray
    cols: np.ndarray

    @property
    def pixels(self) -> np.ndarray:
        return self.rows * self.cols

    def split(self, most: int) -> _Windows:
        """The same pixels in windows of at most `most` (at least a row each), cut into bands
        of rows, in the same order."""
        bands = np.maximum(1, most // np.maximum(self.cols, 1))
        parts = np.maximum(1, -(-self.rows // bands))
        first = np.repeat(np.cumsum(parts) - parts, parts)
        k = np.arange(int(parts.sum())) - first
        of = np.repeat(np.arange(len(parts)), parts)
        row0 = self.row0[of] + k * bands[of]
        rows = np.minimum(bands[of], self.row0[of] + self.rows[of] - row0)
        return _Windows(self.tri[of], row0, rows, self.col0[of], self.cols[of])

    def take(self, sl: slice) -> _Windows:
        return _Windows(self.tri[sl], self.row0[sl], self.rows[sl], self.col0[sl], self.cols[sl])

    def pairs(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(N,) the window, panorama row and (unwrapped) column of each pixel of each window."""
        count = self.pixels
        of = np.repeat(np.arange(len(count)), count)
        k = np.arange(int(count.sum())) - np.repeat(np.cumsum(count) - count, count)
        return of, self.row0[of] + k // self.cols[of], self.col0[of] + k % self.cols[of]


def _rasterise(planes: tuple[np.ndarray, np.ndarray, np.ndarray], windows: _Windows, dirs: np.ndarray,
               frame: tuple[int, int, int], best: np.ndarray, out: dict) -> None:
    """Depth-test the triangles' pixels in `windows` into the buffers, which hold the pixels of
    a window of the panorama (`frame`: first row, first column, panorama width): `dirs` (h, w, 3).
    `planes`: the triangles' `_edge_normals`, normals and normals' dot products with a corner."""
    h, w = dirs.shape[:2]
    win_row, win_col, full_width = frame
    of, rows, cols = windows.pairs()
    rows, cols = rows - win_row, np.mod(cols - win_col, full_width)
    keep = np.flatnonzero((rows >= 0) & (rows < h) & (cols < w))
    tri, rows, cols = windows.tri[of[keep]], rows[keep], cols[keep]
    rays = dirs[rows, cols]  # (N, 3)
    # One window's triangle is broadcast over its pixels rather than gathered for each.
    one = len(windows.tri) == 1
    each = windows.tri[0] if one else tri
    # Unnormalised barycentric weights: each ray's side of the planes through the origin and an edge.
    edge_normals, normal, offset = planes
    weights = np.einsum("...kc,...c->...k", edge_normals[each], rays)
    inside = (weights >= -1e-12 * np.abs(weights).max(axis=1, keepdims=True)).all(axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        dist = offset[each] / np.einsum("...c,...c->...", normal[each], rays)
    ok = np.flatnonzero(inside & (dist > 0.0) & np.isfinite(dist))
    if len(ok) == 0:
        return
    pix, depth, tri, weights = rows[ok] * w + cols[ok], dist[ok], tri[ok], weights[ok]
    first = np.ones(len(pix), dtype=bool)
    if not one:
        # The nearest of each pixel's hits, the first triangle's on a tie (a stable sort).
        order = np.lexsort((depth, pix))
        pix, depth, tri, weights = pix[order], depth[order], tri[order], weights[order]
        first[1:] = pix[1:] != pix[:-1]
    closer = first.copy()
    closer[first] = depth[first] < best.ravel()[pix[first]]
    pix, depth, tri, weights = pix[closer], depth[closer], tri[closer], weights[closer]
    best.ravel()[pix] = depth
    out["tri"].ravel()[pix] = tri
    out["bary"].reshape(-1, 2)[pix] = (weights / weights.sum(axis=1, keepdims=True))[:, 1:]


def _batches(pixels: np.ndarray) -> list[slice]:
    """Runs of consecutive windows of `pixels` each, at most _BATCH_PIXELS in all (or one
    window), a window of _WIDE pixels or more alone."""
    end = np.cumsum(pixels)
    wide = np.flatnonzero(pixels >= _WIDE)
    out, i0 = [], 0
    while i0 < len(end):
        i1 = int(np.searchsorted(end, (end[i0 - 1] if i0 else 0) + _BATCH_PIXELS, side="right"))
        next_wide = wide[np.searchsorted(wide, i0):][:1]
        if len(next_wide):
            i1 = i0 + 1 if next_wide[0] == i0 else min(i1, int(next_wide[0]))
        out.append(slice(i0, max(i1, i0 + 1)))
        i0 = out[-1].stop
    return out


def trace_panorama(triangles: np.ndarray, width: int, height: int, *,
                   window: tuple[int, int, int, int] | None = None,
                   projection: Projection | None = None) -> PanoramaHits:
    """First hit of each pixel centre's ray from the origin among `triangles` (T, 3, 3), over
    the whole W x H panorama or only its `window` (first row, rows, first column, columns;
    the columns wrap around the seam): the hits then have the window's shape. Where two
    triangles meet a ray at the same depth, the first of them is hit. `projection`: the
    triangles' `project`, where the caller holds it.

    Each triangle is tested at the pixels of its exact window (`_uv_window`), batches of
    triangles at once: the cost follows the pixels the triangles cover and their count, so
    a mesh of many sub-pixel triangles costs about what its outline's pixels do."""
    row_start, nrows_w, col_start, ncols_w = window or (0, height, 0, width)
    dirs = window_directions(width, height, (row_start, nrows_w, col_start, ncols_w))
    best = np.full((nrows_w, ncols_w), np.inf)
    out = {"tri": np.full((nrows_w, ncols_w), -1, dtype=np.int64), "bary": np.zeros((nrows_w, ncols_w, 2))}
    p = project(triangles) if projection is None else projection
    seen = np.flatnonzero(p.seen)
    row0, nrows, col0, ncols = _uv_window(p.take(seen), width, height)
    # Only the rows inside the window are worth testing.
    row1 = np.minimum(row0 + nrows, row_start + nrows_w)
    row0 = np.maximum(row0, row_start)
    some = np.flatnonzero((row1 > row0) & (ncols > 0))
    windows = _Windows(seen[some], row0[some], (row1 - row0)[some], col0[some], ncols[some]).split(_BATCH_PIXELS)
    planes = (p.edge_normals, p.normal, p.offset)
    for batch in _batches(windows.pixels):
        # In the triangles' order: the earlier batch keeps a tie of depth.
        _rasterise(planes, windows.take(batch), dirs, (row_start, col_start, width), best, out)
    distance = np.where(np.isfinite(best), best, 0.0)
    return PanoramaHits(tri=out["tri"], distance=distance, bary=out["bary"], directions=dirs)


def window_directions(width: int, height: int, window: tuple[int, int, int, int]) -> np.ndarray:
    """(rows, cols, 3) unit directions through the pixel centres of a window (first row, rows,
    first column, columns) of a W x H panorama; the columns wrap around the seam."""
    row0, rows, col0, cols = window
    grid = np.broadcast_arrays((row0 + np.arange(rows))[:, None], np.mod(col0 + np.arange(cols), width)[None, :])
    return latlong.pixel_directions_at(*grid, width, height)


def _ray_distances(origins: np.ndarray, directions: np.ndarray, triangles: np.ndarray):
    """Yield (first triangle index, (N, n) t of each ray at n triangles, inf where missed),
    chunk by chunk over all triangles: brute force, for a few rays."""
    o = np.asarray(origins, dtype=np.float64)
    d = np.asarray(directions, dtype=np.float64)
    v0, e1, e2 = triangles[:, 0], triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]
    per = max(1, _PAIR_CHUNK // max(len(o), 1))
    for j0 in range(0, len(triangles), per):
        sl = slice(j0, j0 + per)
        p = np.cross(d[:, None, :], e2[None, sl])
        det = np.einsum("tc,ntc->nt", e1[sl], p)
        ok = np.abs(det) > 1e-20
        inv = 1.0 / np.where(ok, det, 1.0)
        t_vec = o[:, None, :] - v0[None, sl]
        u = np.einsum("ntc,ntc->nt", t_vec, p) * inv
        q = np.cross(t_vec, e1[None, sl])
        v = np.einsum("nc,ntc->nt", d, q) * inv
        t = np.einsum("tc,ntc->nt", e2[sl], q) * inv
        yield j0, np.where(ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t > 0.0), t, np.inf)


def first_hits(origins: np.ndarray, directions: np.ndarray, triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N,) the first of `triangles` (T, 3, 3) each ray origin + t direction (t > 0) hits, -1
    for none, and its t (inf for none)."""
    best = np.full(len(origins), np.inf)
    index = np.full(len(origins), -1, dtype=np.int64)
    for j0, t in _ray_distances(origins, directions, triangles):
        k = t.argmin(axis=1)
        tk = t[np.arange(len(t)), k]
        closer = tk < best
        best[closer], index[closer] = tk[closer], j0 + k[closer]
    return index, best


def crossings(origins: np.ndarray, directions: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(N,) how many of `triangles` each ray crosses (odd: the origin is inside a closed mesh)."""
    count = np.zeros(len(origins), dtype=np.int64)
    for _, t in _ray_distances(origins, directions, triangles):
        count += np.isfinite(t).sum(axis=1)
    return count
