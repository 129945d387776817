"""Where the object may cast a shadow of an important sender worth computing exactly."""
from __future__ import annotations

import numpy as np

from ..light.planner import shadow_volume
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
    # |p - c|^2 expanded: a matrix product instead of an (N, I, 3) array of differences.
    d2 = np.maximum(np.einsum("ij,ij->i", points, points)[:, None] - 2.0 * points @ imp_c.T
                    + np.einsum("ij,ij->i", imp_c, imp_c)[None], 0.0) + imp_r[None] ** 2
    bound = b_y[None] * area[None] / (np.pi * d2)
    worth = bound >= params.significance * np.maximum(e_points @ LUMA, 1e-30)[:, None]
    return shadow_volume(points, imp_c, imp_r, target.centre, target.radius + np.asarray(margin), only=worth)
