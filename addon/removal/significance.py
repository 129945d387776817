"""Where the object may cast a shadow of an important sender worth computing exactly."""
from __future__ import annotations

import numpy as np

from ..light.planner import in_shadow_volume
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
    # Sender by sender: (N, I) temporaries of a window-lit room's half a million pixels would
    # cost more in memory traffic than the arithmetic.
    least = np.pi * params.significance * np.maximum(e_points @ LUMA, 1e-30)
    obj_radius = np.broadcast_to(target.radius + np.asarray(margin, dtype=np.float64), (len(points),))
    out = np.zeros((len(points), len(imp)), dtype=bool)
    for s in range(len(imp)):
        gap = points - imp_c[s]
        rows = np.flatnonzero(b_y[s] * area[s] >= least * (np.einsum("ij,ij->i", gap, gap) + imp_r[s] ** 2))
        out[rows, s] = in_shadow_volume(points[rows], imp_c[s], imp_r[s], target.centre, obj_radius[rows])
    return out
