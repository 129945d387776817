"""Where the removed object can change the light at all, decided before any costly step.

Conservative bounding-sphere tests: a receiver is in the shadow volume of the object from a
sender when the segment towards the sender's centre passes within (object radius + sender
radius) of the object's centre; it is in the object's neighbourhood when the object's
bounding sphere fills more than `reach` of its view (solid-angle fraction (r / d)^2).
"""
from __future__ import annotations

import numpy as np


def in_shadow_volume(points: np.ndarray, centre: np.ndarray, radius: float, obj_centre: np.ndarray,
                     obj_radius: np.ndarray) -> np.ndarray:
    """(N,) whether receivers may be shadowed by the object (radius per receiver, to widen the
    test for receivers that stand for an area) from the sender in the sphere (centre, radius)."""
    d = centre - points
    length2 = np.maximum(np.einsum("ij,ij->i", d, d), 1e-300)
    t = np.clip(np.einsum("ij,ij->i", obj_centre - points, d) / length2, 0, 1)
    gap = points + t[:, None] * d - obj_centre
    return np.einsum("ij,ij->i", gap, gap) <= (obj_radius + radius) ** 2


def neighbourhood(points: np.ndarray, obj_centre: np.ndarray, obj_radius: float, *, reach: float) -> np.ndarray:
    """(N,) whether the object's bounding sphere covers more than `reach` of the view."""
    return np.linalg.norm(points - obj_centre, axis=1) < obj_radius / np.sqrt(reach)
