"""Regular subdivision of triangles into patches, and lattice interpolation.

Triangle t with level n is cut into n^2 congruent patches whose corners form a triangular
lattice of (n+1)(n+2)/2 vertices (i/n, j/n in the triangle's barycentric frame). A point given
by its triangle and barycentric weights falls in exactly one patch; smooth quantities known at
lattice vertices are interpolated there linearly (the triangle analogue of the thesis's
bilinear interpolation between grid corners).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def _vertex_index(i: np.ndarray, j: np.ndarray, n: np.ndarray) -> np.ndarray:
    return i * (n + 1) - i * (i - 1) // 2 + j


def _lower_index(i, j, n):
    return i * n - i * (i - 1) // 2 + j


def _upper_index(i, j, n):
    return n * (n + 1) // 2 + i * (n - 1) - i * (i - 1) // 2 + j


def _template(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Lattice coordinates (V, 2) and patch corner indices (n^2, 3) of one level-n triangle."""
    ij = np.array([(i, j) for i in range(n + 1) for j in range(n + 1 - i)], dtype=np.int64)
    corners = np.zeros((n * n, 3), dtype=np.int64)
    ii, jj = np.array([(i, j) for i in range(n) for j in range(n - i)], dtype=np.int64).T
    nn = np.full_like(ii, n)
    corners[_lower_index(ii, jj, nn)] = np.stack(
        [_vertex_index(ii, jj, nn), _vertex_index(ii + 1, jj, nn), _vertex_index(ii, jj + 1, nn)], axis=1
    )
    up = ii + jj <= n - 2
    iu, ju, nu = ii[up], jj[up], nn[up]
    corners[_upper_index(iu, ju, nu)] = np.stack(
        [_vertex_index(iu + 1, ju, nu), _vertex_index(iu + 1, ju + 1, nu), _vertex_index(iu, ju + 1, nu)], axis=1
    )
    return ij / max(n, 1), corners


@dataclass
class Lattice:
    """Patches and lattice vertices of a set of triangles; level 0 leaves a triangle out."""

    levels: np.ndarray  # (T,)
    vertex_offset: np.ndarray  # (T,) first lattice vertex of each triangle
    patch_offset: np.ndarray  # (T,) first patch of each triangle
    vertices: np.ndarray  # (V, 3)
    vertex_tri: np.ndarray  # (V,)
    patch_corners: np.ndarray  # (P, 3) lattice vertex indices
    patch_tri: np.ndarray  # (P,)

    @property
    def n_patches(self) -> int:
        return len(self.patch_tri)

    def patch_triangles(self) -> np.ndarray:
        return self.vertices[self.patch_corners]

    def locate(self, tri: np.ndarray, bary: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Patch index (N,), its lattice vertices (N, 3) and their weights (N, 3) for points on triangles.

        bary holds the weights of the triangle's vertices 1 and 2; the triangles must have level > 0.
        """
        n = self.levels[tri]
        x = bary[:, 0] * n
        y = bary[:, 1] * n
        i = np.clip(np.floor(x).astype(np.int64), 0, n - 1)
        j = np.clip(np.floor(y).astype(np.int64), 0, n - 1 - i)
        fx = np.clip(x - i, 0.0, 1.0)
        fy = np.clip(y - j, 0.0, 1.0)
        upper = (fx + fy > 1.0) & (i + j <= n - 2)
        fy = np.where(~upper & (fx + fy > 1.0), 1.0 - fx, fy)  # clamp onto the lattice's far edge
        local = np.where(upper, _upper_index(i, j, n), _lower_index(i, j, n))
        patch = self.patch_offset[tri] + local
        w = np.where(
            upper[:, None],
            np.stack([1.0 - fy, fx + fy - 1.0, 1.0 - fx], axis=1),
            np.stack([1.0 - fx - fy, fx, fy], axis=1),
        )
        return patch, self.patch_corners[patch], w


def build_lattice(triangles: np.ndarray, levels: np.ndarray) -> Lattice:
    """Subdivide triangle t into levels[t]^2 patches (level 0: left out)."""
    levels = np.asarray(levels, dtype=np.int64)
    vertex_count = np.where(levels > 0, (levels + 1) * (levels + 2) // 2, 0)
    patch_count = levels * levels
    vertex_offset = np.concatenate([[0], np.cumsum(vertex_count)[:-1]]).astype(np.int64)
    patch_offset = np.concatenate([[0], np.cumsum(patch_count)[:-1]]).astype(np.int64)
    vertices = np.zeros((int(vertex_count.sum()), 3))
    vertex_tri = np.zeros(int(vertex_count.sum()), dtype=np.int64)
    corners = np.zeros((int(patch_count.sum()), 3), dtype=np.int64)
    patch_tri = np.zeros(int(patch_count.sum()), dtype=np.int64)
    for n in np.unique(levels[levels > 0]):
        members = np.flatnonzero(levels == n)
        st, template = _template(int(n))
        a = triangles[members, 0]
        pos = (
            a[:, None, :]
            + st[None, :, 0, None] * (triangles[members, 1] - a)[:, None, :]
            + st[None, :, 1, None] * (triangles[members, 2] - a)[:, None, :]
        )
        vidx = vertex_offset[members][:, None] + np.arange(len(st))[None, :]
        vertices[vidx] = pos
        vertex_tri[vidx] = members[:, None]
        pidx = patch_offset[members][:, None] + np.arange(len(template))[None, :]
        corners[pidx] = vertex_offset[members][:, None, None] + template[None]
        patch_tri[pidx] = members[:, None]
    return Lattice(levels, vertex_offset, patch_offset, vertices, vertex_tri, corners, patch_tri)


def split_triangles(tris: np.ndarray, k: int) -> np.ndarray:
    """(S, k*k, 3, 3) the k^2 congruent sub-triangles of each triangle (S, 3, 3), in the order
    of `triangle_samples`."""
    st, corners = _template(k)
    st = st[corners]  # (k^2, 3, 2) barycentric (s, t) of the sub-triangles' corners
    a = tris[:, None, None, 0]
    return (a + st[None, ..., 0, None] * (tris[:, None, None, 1] - a)
            + st[None, ..., 1, None] * (tris[:, None, None, 2] - a))


def triangle_samples(tris: np.ndarray, k: int) -> np.ndarray:
    """(S, k*k, 3) centroids of the k^2 sub-triangles of each triangle (S, 3, 3)."""
    return split_triangles(tris, k).mean(axis=2)


def levels_for_size(triangles: np.ndarray, size: np.ndarray | float, *, max_level: int = 64) -> np.ndarray:
    """Subdivision level giving patches whose longest edge is about `size` (per triangle or scalar)."""
    edges = np.linalg.norm(triangles - np.roll(triangles, 1, axis=1), axis=2).max(axis=1)
    return np.clip(np.ceil(edges / np.maximum(size, 1e-12)), 1, max_level).astype(np.int64)


def levels_for_count(triangles: np.ndarray, target: int, *, max_level: int = 64) -> np.ndarray:
    """Levels from one common patch size chosen so the total number of patches is near `target`."""
    edges = np.linalg.norm(triangles - np.roll(triangles, 1, axis=1), axis=2).max(axis=1)
    lo, hi = 1e-6 * edges.max(), edges.max()
    for _ in range(40):  # bisection on the size: the count falls as the size grows
        mid = np.sqrt(lo * hi)
        count = (np.clip(np.ceil(edges / mid), 1, max_level) ** 2).sum()
        lo, hi = (mid, hi) if count > target else (lo, mid)
    return levels_for_size(triangles, hi, max_level=max_level)
