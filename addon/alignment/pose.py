"""A correction of an object's pose on a horizontal support: a shift, a turn about the vertical
through its bottom centre, a uniform scale about that point."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Pose:
    """World-space correction: the bottom centre moves by `shift` (m), the object turns by
    `turn` (radians, counter-clockwise seen from above) and scales by `scale` about it."""

    shift: np.ndarray
    turn: float
    scale: float

    @classmethod
    def identity(cls) -> Pose:
        return cls(np.zeros(3), 0.0, 1.0)

    def matrix(self, pivot: np.ndarray) -> np.ndarray:
        """(4, 4) world matrix of the correction about `pivot` (the bottom centre)."""
        c, s = np.cos(self.turn), np.sin(self.turn)
        linear = self.scale * np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        m = np.eye(4)
        m[:3, :3] = linear
        m[:3, 3] = np.asarray(pivot) + self.shift - linear @ np.asarray(pivot)
        return m

    def stepped(self, step: np.ndarray) -> Pose:
        """This pose followed by a small one, `step` = (dx, dy, dz, d turn, d log scale) about
        the moved pivot (turns and scales about one point commute)."""
        return Pose(self.shift + step[:3], self.turn + float(step[3]), self.scale * float(np.exp(step[4])))


def bottom_centre(points: np.ndarray) -> np.ndarray:
    """(3,) the centre of the bounding box's bottom: where the object stands on its support."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return np.array([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]])


def apply(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (..., 3) moved by a (4, 4) matrix."""
    return np.asarray(points) @ matrix[:3, :3].T + matrix[:3, 3]
