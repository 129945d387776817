"""Where the object may cast a shadow of an important sender worth computing exactly: the
conservative bounding-sphere test of its shadow volume (the segment from a receiver towards the
sender's centre passes within the object's radius plus the sender's of the object's centre),
where the sender's unblocked light is worth it."""
from __future__ import annotations

import numpy as np

from ..light.radiosity import LUMA
from ..light.transport import Senders
from ..quality import Params
from .target import Target


def sender_spheres(senders: Senders, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, 3) centres and (n,) radii of spheres around the senders `idx`."""
    tris = senders.triangles[idx]
    centres = tris.mean(axis=1)
    return centres, np.linalg.norm(tris - centres[:, None, :], axis=2).max(axis=1)


def significant(senders: Senders, imp: np.ndarray, points: np.ndarray, e_points: np.ndarray, target: Target,
                params: Params, *, margin: float | np.ndarray = 0.0) -> np.ndarray:
    """(N, I) receiver-sender pairs where the object may cast a shadow worth computing exactly:
    inside the shadow volume, and the sender's unblocked light is at least `significance` of E
    (the receivers' (N, 3) `e_points`). `margin` widens the object for receivers that stand for
    an area."""
    imp_c, imp_r = sender_spheres(senders, imp)
    b_y = senders.radiosity[imp] @ LUMA
    tris = senders.triangles[imp]
    area = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1) / 2
    # Sender by sender over (N,) vectors, relative to the object's centre: with |q|^2 of every
    # point known, the distance to a sender and the shadow volume's test (the segment towards
    # the sender's centre passes within the two radii of the object's centre) cost a
    # matrix-vector product and a few vector operations a sender, not (N, 3) arrays of them.
    least = np.pi * params.significance * np.maximum(e_points @ LUMA, 1e-30)
    reach2 = (target.radius + np.asarray(margin, dtype=np.float64) + imp_r[:, None]) ** 2  # (I, N or 1)
    q = points - target.centre
    qq = np.einsum("ij,ij->i", q, q)
    ends = imp_c - target.centre
    out = np.zeros((len(points), len(imp)), dtype=bool)
    for s in range(len(imp)):
        qc = q @ ends[s]
        dd = np.maximum(ends[s] @ ends[s] - 2.0 * qc + qq, 0.0)  # |p - c|^2
        rows = np.flatnonzero(b_y[s] * area[s] >= least * (dd + imp_r[s] ** 2))
        toward = qq[rows] - qc[rows]  # (o - p) . (c - p)
        t = np.clip(toward / np.maximum(dd[rows], 1e-300), 0.0, 1.0)
        gap2 = qq[rows] - 2.0 * t * toward + t * t * dd[rows]
        out[rows, s] = gap2 <= np.broadcast_to(reach2[s], (len(points),))[rows]
    return out
