"""Where the removed object can change the light at all, decided before any costly step.

A conservative bounding-sphere test: a receiver is in the object's neighbourhood when the
object's bounding sphere fills more than `reach` of its view (solid-angle fraction (r / d)^2).
The shadow volumes are `removal.significance`'s.
"""
from __future__ import annotations

import numpy as np


def neighbourhood(points: np.ndarray, obj_centre: np.ndarray, obj_radius: float, *, reach: float) -> np.ndarray:
    """(N,) whether the object's bounding sphere covers more than `reach` of the view."""
    return np.linalg.norm(points - obj_centre, axis=1) < obj_radius / np.sqrt(reach)
