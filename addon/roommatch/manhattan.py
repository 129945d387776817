"""Manhattan snapping: the floor polygon whose walls meet at right angles and whose corners
reproject closest (in pixels) onto the clicks.

In the probe's frame at unit camera height (floor at z = -1), walls run along two axes
a0 = (cos t, sin t) and a1 = (-sin t, cos t); wall i lies on the line q . n_i = c_i with n_i the
normal of its axis, and corner i, where wall i - 1 meets wall i, is the crossing of their lines.
The turn t and the offsets c are fitted by Levenberg-Marquardt steps on the corners' pixel
offsets from the clicks: far corners, whose clicks say least about where they are, pull least.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DimredError
from .projection import pixel_offsets, project

_STEPS = 50
_STEP = 1e-6  # numeric derivative step (radians, unit-height lengths)


@dataclass(frozen=True)
class Snapped:
    """The snapped corners (n, 2) at unit camera height, the walls' turn (radians, in
    [-pi/4, pi/4)) and each wall's axis (0 or 1)."""

    corners: np.ndarray
    turn: float
    axes: np.ndarray


def snap(corners: np.ndarray, clicks: np.ndarray, width: int, height: int,
         rotation: np.ndarray | None = None) -> Snapped:
    """Snap the unit-height floor polygon `corners` (n, 2), seen at the `clicks` (n, 2)."""
    q = np.asarray(corners, dtype=np.float64)
    n = len(q)
    edges = np.roll(q, -1, axis=0) - q
    angle = np.arctan2(edges[:, 1], edges[:, 0])
    weight = np.linalg.norm(edges, axis=1)
    turn = float(np.arctan2(np.sum(weight * np.sin(4 * angle)), np.sum(weight * np.cos(4 * angle))) / 4.0)
    axes = np.mod(np.round((angle - turn) / (np.pi / 2)), 2).astype(np.int64)
    same = np.flatnonzero(axes == np.roll(axes, -1))
    if same.size:
        i = int(same[0])
        raise DimredError(f"walls {i} and {(i + 1) % n} run the same way, so corner {(i + 1) % n} is no corner of "
                          "a room with right-angled walls: remove that click or turn Manhattan snapping off")
    params = np.concatenate([[turn], _offsets(q, turn, axes)])

    def residuals(p: np.ndarray) -> np.ndarray:
        points = np.concatenate([_corners(p, axes), -np.ones((n, 1))], axis=1)
        return pixel_offsets(project(points, width, height, rotation), clicks, width).ravel()

    params = _levenberg_marquardt(residuals, params)
    return Snapped(corners=_corners(params, axes), turn=float(params[0]), axes=axes)


def _axes(turn: float) -> np.ndarray:
    c, s = np.cos(turn), np.sin(turn)
    return np.array([[c, s], [-s, c]])


def _offsets(q: np.ndarray, turn: float, axes: np.ndarray) -> np.ndarray:
    """Each wall's offset along its normal: the mean of its two ends'."""
    normals = _axes(turn)[1 - axes]
    ends = q + np.roll(q, -1, axis=0)
    return 0.5 * np.sum(ends * normals, axis=1)


def _corners(params: np.ndarray, axes: np.ndarray) -> np.ndarray:
    a = _axes(params[0])
    c = params[1:]
    before = np.roll(c, 1)  # wall i - 1, which ends at corner i
    before_axes = np.roll(axes, 1)
    # Wall i's offset is the corner's coordinate along the normal of its axis; a wall of axis 0
    # has normal a1 and one of axis 1 normal a0.
    along0 = np.where(axes == 1, c, before)
    along1 = np.where(before_axes == 0, before, c)
    return along0[:, None] * a[0] + along1[:, None] * a[1]


def _levenberg_marquardt(residuals, params: np.ndarray) -> np.ndarray:
    r = residuals(params)
    cost = float(r @ r)
    damping = 1e-3
    for _ in range(_STEPS):
        jacobian = np.stack([(residuals(params + e) - residuals(params - e)) / (2 * _STEP)
                             for e in _STEP * np.eye(len(params))], axis=1)
        normal = jacobian.T @ jacobian
        gradient = jacobian.T @ r
        while damping < 1e8:
            step = np.linalg.solve(normal + damping * np.diag(np.diag(normal) + 1e-12), -gradient)
            trial = params + step
            r_trial = residuals(trial)
            cost_trial = float(r_trial @ r_trial)
            if cost_trial < cost:
                break
            damping *= 10.0
        else:
            return params
        done = cost - cost_trial < 1e-12 * max(cost, 1e-12)
        params, r, cost = trial, r_trial, cost_trial
        damping = max(damping / 10.0, 1e-9)
        if done:
            break
    return params
