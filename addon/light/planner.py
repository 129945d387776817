"""Where the removed object can change the light at all, decided before any costly step.

Conservative bounding-sphere tests: a receiver is in the shadow volume of the object from a
sender when the segment towards the sender's centre passes within (object radius + sender
radius) of the object's centre; it is in the object's neighbourhood when the object's
bounding sphere fills more than `reach` of its view (solid-angle fraction (r / d)^2).
"""
from __future__ import annotations

import numpy as np


def shadow_volume(points: np.ndarray, centres: np.ndarray, radii: np.ndarray, obj_centre: np.ndarray,
                  obj_radius: float | np.ndarray, *, only: np.ndarray | None = None) -> np.ndarray:
    """(N, S) whether receiver n may be shadowed by the object from sender s (obj_radius may be
    per receiver, to widen the test for receivers that stand for an area); with `only` (N, S)
    bool, just those pairs are tested and the rest are False."""
    obj_radius = np.broadcast_to(np.asarray(obj_radius, dtype=np.float64), (len(points),))
    out = np.zeros((len(points), len(centres)), dtype=bool)
    for s in range(len(centres)):
        rows = np.arange(len(points)) if only is None else np.flatnonzero(only[:, s])
        p = points[rows]
        d = centres[s] - p
        length2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
        t = np.clip(np.einsum("ij,ij->i", obj_centre - p, d) / length2, 0, 1)
        gap = p + t[:, None] * d - obj_centre
        out[rows, s] = np.einsum("ij,ij->i", gap, gap) <= (obj_radius[rows] + radii[s]) ** 2
    return out


def neighbourhood(points: np.ndarray, obj_centre: np.ndarray, obj_radius: float, *, reach: float) -> np.ndarray:
    """(N,) whether the object's bounding sphere covers more than `reach` of the view."""
    return np.linalg.norm(points - obj_centre, axis=1) < obj_radius / np.sqrt(reach)
