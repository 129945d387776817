"""First hits of rays from the probe among a few candidate triangles per ray.

A full-resolution pixel sees one of the triangles its working-resolution neighbours see (the
proxy's triangles are large next to a pixel), so testing those few finds its surface without
rasterising the whole scene again at full size.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_CHUNK = 1 << 17  # rays per block: bounds the (rays x candidates x 3) temporaries


@dataclass(frozen=True)
class CandidateHits:
    """Per ray: the first candidate triangle hit (-1 for none), its distance along the unit
    direction (inf for none) and the barycentric weights of vertices 1 and 2 there."""

    tri: np.ndarray
    distance: np.ndarray
    bary: np.ndarray


def hits_among(directions: np.ndarray, triangles: np.ndarray, candidates: np.ndarray) -> CandidateHits:
    """The first hit of each ray from the origin along `directions` (N, 3) among its row of
    `candidates` (N, K) indices into `triangles` (T, 3, 3), -1 meaning no candidate."""
    n = len(directions)
    tri = np.full(n, -1, dtype=np.int64)
    distance = np.full(n, np.inf)
    bary = np.zeros((n, 2))
    for start in range(0, n, _CHUNK):
        block = slice(start, start + _CHUNK)
        tri[block], distance[block], bary[block] = _block(directions[block], triangles, candidates[block])
    return CandidateHits(tri, distance, bary)


def _block(d: np.ndarray, triangles: np.ndarray, cand: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    # By component on (n, K) arrays: np.cross and einsum on (n, K, 3) ones took twice as long
    # for the same products, summed in the same order.
    at = np.maximum(cand, 0)
    v0x, v0y, v0z = (triangles[:, 0, c][at] for c in range(3))
    ax, ay, az = (triangles[:, 1, c][at] - w for c, w in enumerate((v0x, v0y, v0z)))
    bx, by, bz = (triangles[:, 2, c][at] - w for c, w in enumerate((v0x, v0y, v0z)))
    dx, dy, dz = d[:, 0, None], d[:, 1, None], d[:, 2, None]
    px, py, pz = dy * bz - dz * by, dz * bx - dx * bz, dx * by - dy * bx
    det = ax * px + ay * py + az * pz
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        sx, sy, sz = -v0x, -v0y, -v0z  # the origin minus the first corner
        b1 = (sx * px + sy * py + sz * pz) * inv
        qx, qy, qz = sy * az - sz * ay, sz * ax - sx * az, sx * ay - sy * ax
        b2 = (dx * qx + dy * qy + dz * qz) * inv
        dist = (bx * qx + by * qy + bz * qz) * inv
    # A ray through a shared edge or corner belongs to some candidate: the small slack keeps
    # the seam between two triangles of one plane from leaking through.
    slack = 1e-9
    ok = ((cand >= 0) & np.isfinite(dist) & (dist > 0.0) & (b1 >= -slack) & (b2 >= -slack)
          & (b1 + b2 <= 1.0 + slack))
    dist = np.where(ok, dist, np.inf)
    best = dist.argmin(axis=1)
    rows = np.arange(len(d))
    found = np.isfinite(dist[rows, best])
    tri = np.where(found, cand[rows, best], -1)
    bary = np.stack([b1[rows, best], b2[rows, best]], axis=1)
    return tri, dist[rows, best], np.where(found[:, None], bary, 0.0)
