"""Points on a mesh's silhouette as seen from the probe centre: they lie on the mesh, so they
move with its pose continuously (a rasterised outline would move in whole pixels)."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Topology:
    """The edges of a triangle soup with shared vertices merged: `edges` (E, 2) and `apex`
    (E, 2), the vertex opposite the edge in each of its first two triangles (-1 for a boundary
    edge), indexing `vertices`."""

    vertices: np.ndarray  # (V, 3)
    edges: np.ndarray
    apex: np.ndarray


def topology(triangles: np.ndarray) -> Topology:
    """Merge the vertices of `triangles` (T, 3, 3) that coincide (to a millionth of the mesh's
    size) and list its edges with their neighbouring triangles."""
    pts = triangles.reshape(-1, 3)
    size = float(np.ptp(pts, axis=0).max()) or 1.0
    keys = np.round(pts / (1e-6 * size)).astype(np.int64)
    _, first, index = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    corner = index.reshape(-1, 3)
    vertices = pts[first]
    a = corner[:, [0, 1, 2]].ravel()
    b = corner[:, [1, 2, 0]].ravel()
    apex = corner[:, [2, 0, 1]].ravel()
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    key = lo * len(vertices) + hi
    order = np.argsort(key, kind="stable")
    key, apex = key[order], apex[order]
    start = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    count = np.diff(np.r_[start, len(key)])
    second = np.where(count >= 2, apex[np.minimum(start + 1, len(key) - 1)], -1)
    edges = np.stack([key[start] // len(vertices), key[start] % len(vertices)], axis=1)
    return Topology(vertices=vertices, edges=edges, apex=np.stack([apex[start], second], axis=1))


def silhouette_points(vertices: np.ndarray, topo: Topology, *, spacing: float) -> np.ndarray:
    """(N, 3) points every `spacing` radians along the edges that fold away from the probe at
    the origin (both neighbouring triangles on one side of the plane through the probe and
    the edge, or a boundary edge), `vertices` (V, 3) being the posed vertices in the probe
    frame. Independent of the triangles' winding."""
    a, b = vertices[topo.edges[:, 0]], vertices[topo.edges[:, 1]]
    normal = np.cross(a, b)
    side = [np.einsum("ij,ij->i", normal, vertices[topo.apex[:, k]]) for k in (0, 1)]
    fold = (topo.apex[:, 1] < 0) | (side[0] * side[1] > 0)
    a, b = a[fold], b[fold]
    ua = a / np.linalg.norm(a, axis=1, keepdims=True)
    ub = b / np.linalg.norm(b, axis=1, keepdims=True)
    angle = np.arccos(np.clip(np.einsum("ij,ij->i", ua, ub), -1.0, 1.0))
    count = np.maximum(1, np.ceil(angle / spacing).astype(np.int64))
    edge = np.repeat(np.arange(len(a)), count)
    within = np.arange(len(edge)) - np.repeat(np.cumsum(count) - count, count)
    t = ((within + 0.5) / count[edge])[:, None]
    return a[edge] * (1.0 - t) + b[edge] * t
