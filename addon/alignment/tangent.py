"""The gnomonic plane tangent to the sphere of directions at the object: outlines compared there
are free of the lat-long image's stretch near the poles and its seam."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TangentPlane:
    """Projection of probe-frame points onto the plane touching the unit sphere at `axis`;
    a unit there is a radian at the axis."""

    axis: np.ndarray
    e1: np.ndarray
    e2: np.ndarray

    @classmethod
    def at(cls, direction: np.ndarray) -> TangentPlane:
        axis = np.asarray(direction, dtype=np.float64) / np.linalg.norm(direction)
        helper = np.array([0.0, 0.0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        e1 = np.cross(helper, axis)
        e1 /= np.linalg.norm(e1)
        return cls(axis, e1, np.cross(axis, e1))

    def project(self, points: np.ndarray) -> np.ndarray:
        """(N, 2) plane coordinates of probe-frame points (N, 3) in front of the plane."""
        depth = points @ self.axis
        return np.stack([points @ self.e1, points @ self.e2], axis=1) / depth[:, None]

    def jacobian(self, points: np.ndarray) -> np.ndarray:
        """(N, 2, 3) derivative of `project` at the points."""
        depth = (points @ self.axis)[:, None]
        rows = []
        for e in (self.e1, self.e2):
            rows.append((e[None, :] * depth - (points @ e)[:, None] * self.axis[None, :]) / depth**2)
        return np.stack(rows, axis=1)

    def in_front(self, points: np.ndarray) -> np.ndarray:
        return points @ self.axis > 1e-9 * np.linalg.norm(points, axis=-1)
