"""Vectorised ray casting: what each panorama pixel sees, and the hits of a few rays.

`trace_panorama` rasterises every triangle into the lat-long image as seen from the probe
(the origin of the probe frame) with a depth buffer: a ray from the probe is a pixel, so this
is exact first-hit ray casting without a loop over pixels. `first_hits` and `crossings` test
a few rays against every triangle. Which segments are blocked is `occluders.Occluders`.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import latlong

_EDGE_SAMPLES = 17
_BATCH_PIXELS = 1 << 21
_PAIR_CHUNK = 40_000


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


def _uv_window(tris: np.ndarray, width: int, height: int) -> tuple[np.ndarray, ...]:
    """Conservative pixel windows (row0, rows, col0, cols) of triangles seen from the origin."""
    t = np.linspace(0.0, 1.0, _EDGE_SAMPLES)[None, :, None]
    edges = [tris[:, k, None, :] * (1.0 - t) + tris[:, (k + 1) % 3, None, :] * t for k in range(3)]
    pts = np.concatenate(edges, axis=1)
    u, v = latlong.direction_to_uv(pts)
    rows = (1.0 - v) * height
    # An edge passing close to a pole reaches its highest (lowest) elevation between samples,
    # rows away from the samples' own: take each edge's exact extremes as well.
    extreme = _edge_extreme_rows(tris, height)
    row0 = np.clip(np.floor(np.minimum(rows.min(axis=1), extreme.min(axis=1))) - 2, 0, height - 1).astype(np.int64)
    row1 = np.clip(np.ceil(np.maximum(rows.max(axis=1), extreme.max(axis=1))) + 2, 0, height - 1).astype(np.int64)
    # The u span is the circle minus its largest gap between samples (handles the seam).
    u_sorted = np.sort(u, axis=1)
    gaps = np.diff(np.concatenate([u_sorted, u_sorted[:, :1] + 1.0], axis=1), axis=1)
    widest = gaps.argmax(axis=1)
    start = u_sorted[np.arange(len(u_sorted)), (widest + 1) % u_sorted.shape[1]]
    span = 1.0 - gaps.max(axis=1)
    col0 = np.floor(start * width).astype(np.int64) - 2
    cols = np.ceil(span * width).astype(np.int64) + 5
    # A triangle around a pole covers every column near that pole.
    for pole, edge_row in ((np.array([0.0, 0.0, 1.0]), 0), (np.array([0.0, 0.0, -1.0]), height - 1)):
        inside = _inside(tris, pole[None, :])[:, 0]
        row0 = np.where(inside & (edge_row == 0), 0, row0)
        row1 = np.where(inside & (edge_row == height - 1), height - 1, row1)
        col0 = np.where(inside, 0, col0)
        cols = np.where(inside, width, cols)
    cols = np.minimum(cols, width)
    return row0, row1 - row0 + 1, col0, cols


def _edge_extreme_rows(tris: np.ndarray, height: int) -> np.ndarray:
    """(T, 3) the panorama row (continuous) of each edge's interior extreme of elevation.

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
    return np.arccos(np.clip(z, -1.0, 1.0)) / np.pi * height


def _edge_normals(tris: np.ndarray) -> np.ndarray:
    """(T, 3, 3) normals of the planes through the origin and each edge, pointing inward."""
    a, b, c = tris[:, 0], tris[:, 1], tris[:, 2]
    normals = np.stack([np.cross(b, c), np.cross(c, a), np.cross(a, b)], axis=1)
    sign = np.sign(np.einsum("ij,ij->i", a, np.cross(b, c)))
    return normals * sign[:, None, None]


def _inside(tris: np.ndarray, dirs: np.ndarray) -> np.ndarray:
    """(T, D) whether directions fall inside each triangle's cone from the origin."""
    return (np.einsum("tkc,dc->tdk", _edge_normals(tris), dirs) >= 0.0).all(axis=2)


def _rasterise(tris, tri_ids, row0, nrows, col0, ncols, dirs, window, best, out) -> None:
    """Depth-test one batch of triangles that share a window shape into the buffers, which
    hold the pixels of `window` (first row, first column, panorama width): `dirs` (h, w, 3)."""
    h, w = dirs.shape[:2]
    win_row, win_col, full_width = window
    rows = row0[:, None, None] + np.arange(nrows)[None, :, None] - win_row
    cols = np.mod(col0[:, None, None] + np.arange(ncols)[None, None, :] - win_col, full_width)
    # Rows past the pole or the window's end were clamped onto its last row, and columns
    # outside a partial window onto its last column: the clamped duplicates are dropped.
    in_window = (rows >= 0) & (rows < h) & (cols < w)
    rows = np.broadcast_to(np.clip(rows, 0, h - 1), (len(tris), nrows, ncols))
    cols = np.broadcast_to(np.minimum(cols, w - 1), (len(tris), nrows, ncols))
    rays = dirs[rows, cols]  # (B, nr, nc, 3)
    edge_normals = _edge_normals(tris)
    # Unnormalised barycentric weights: each ray's side of the planes through the origin and an edge.
    weights = np.einsum("bkc,brsc->brsk", edge_normals, rays)
    inside = (weights >= -1e-12 * np.abs(weights).max(axis=3, keepdims=True)).all(axis=3)
    normal = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    normal_dot_ray = np.einsum("bc,brsc->brs", normal, rays)
    normal_dot_corner = np.einsum("bc,bc->b", normal, tris[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        dist = normal_dot_corner[:, None, None] / normal_dot_ray
    ok = inside & (dist > 0.0) & np.isfinite(dist) & in_window
    tri, row, col = np.nonzero(ok)
    if len(tri) == 0:
        return
    pix = rows[tri, row, col] * w + cols[tri, row, col]
    depth = dist[tri, row, col]
    order = np.lexsort((depth, pix))
    pix, depth, tri, row, col = pix[order], depth[order], tri[order], row[order], col[order]
    first = np.ones(len(pix), dtype=bool)
    first[1:] = pix[1:] != pix[:-1]
    pix, depth, tri, row, col = pix[first], depth[first], tri[first], row[first], col[first]
    closer = depth < best.ravel()[pix]
    pix, depth, tri, row, col = pix[closer], depth[closer], tri[closer], row[closer], col[closer]
    bary = weights[tri, row, col]
    bary = bary / bary.sum(axis=1, keepdims=True)
    best.ravel()[pix] = depth
    out["tri"].ravel()[pix] = tri_ids[tri]
    out["bary"].reshape(-1, 2)[pix] = bary[:, 1:]


def trace_panorama(triangles: np.ndarray, width: int, height: int, *,
                   window: tuple[int, int, int, int] | None = None) -> PanoramaHits:
    """First hit of each pixel centre's ray from the origin among `triangles` (T, 3, 3), over
    the whole W x H panorama or only its `window` (first row, rows, first column, columns;
    the columns wrap around the seam): the hits then have the window's shape."""
    row_start, nrows_w, col_start, ncols_w = window or (0, height, 0, width)
    dirs = window_directions(width, height, (row_start, nrows_w, col_start, ncols_w))
    best = np.full((nrows_w, ncols_w), np.inf)
    out = {"tri": np.full((nrows_w, ncols_w), -1, dtype=np.int64), "bary": np.zeros((nrows_w, ncols_w, 2))}
    det = np.einsum("ij,ij->i", triangles[:, 0], np.cross(triangles[:, 1], triangles[:, 2]))
    scale = np.linalg.norm(triangles, axis=2).max(axis=1) ** 3
    seen = np.flatnonzero(np.abs(det) > 1e-12 * scale)  # edge-on triangles cover no pixel centre
    if len(seen):
        row0, nrows, col0, ncols = _uv_window(triangles[seen], width, height)
        # Only the rows inside the window are worth testing.
        row1 = np.minimum(row0 + nrows, row_start + nrows_w)
        row0 = np.maximum(row0, row_start)
        inside = row1 > row0
        seen, row0, nrows, col0, ncols = seen[inside], row0[inside], (row1 - row0)[inside], col0[inside], ncols[inside]
        size = np.maximum(nrows, ncols)
        bucket = np.maximum(2, np.ceil(np.log2(np.maximum(size, 1)))).astype(int)
        frame = (row_start, col_start, width)
        for k in np.unique(bucket):
            members = np.flatnonzero(bucket == k)
            if k <= 6:
                side = 1 << k
                per = max(1, _BATCH_PIXELS // (side * side))
                for i0 in range(0, len(members), per):
                    m = members[i0 : i0 + per]
                    _rasterise(triangles[seen[m]], seen[m], row0[m], side, col0[m], side, dirs, frame, best, out)
            else:
                for m in members:
                    sl = slice(m, m + 1)
                    _rasterise(triangles[seen[sl]], seen[sl], row0[sl], int(nrows[m]), col0[sl], int(ncols[m]),
                               dirs, frame, best, out)
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
