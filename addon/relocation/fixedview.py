"""The fixed-view constraint of a relocation (thesis 5.1, see docs/design.md), in world space (no bpy).

The panorama shows a real object from the probe centre c only, so a move may show no side that
was not photographed: the object turns about the vertical axis through c by an angle (yaw) and
its own orientation turns by the same angle, and its horizontal distance from that axis is
scaled by a factor; its height stays, so it keeps standing on its support plane. Seen from c
the object then keeps the same side towards the viewer; only its elevation changes when the
distance does (a nearer object is seen more from above), and that change is reported.

`Move` is the request; `move_matrix` the world-space transform it means; `move_between`
recovers a Move from two placements and refuses anything else (a tilt, a vertical shift, a
scale, a turn that is not the orbit's).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import DimredError

_TOLERANCE_DEG = 0.5  # angles within this count as equal (a user's rotation snapped to 1 degree passes)
_TOLERANCE_REL = 1e-3  # lengths within this share of the object's distance count as equal


@dataclass(frozen=True)
class Move:
    """yaw: degrees about +Z through the probe centre (counter-clockwise seen from above);
    distance_scale: factor on the horizontal distance from that axis (> 0)."""

    yaw: float = 0.0
    distance_scale: float = 1.0


def check_move(move: Move) -> None:
    """DimredError for a request that no placement satisfies."""
    if not math.isfinite(move.yaw):
        raise DimredError(f"the yaw must be a finite angle in degrees, got {move.yaw}")
    if not math.isfinite(move.distance_scale) or move.distance_scale <= 0.0:
        raise DimredError(
            f"the distance factor must be a positive number, got {move.distance_scale}: it scales the object's "
            "horizontal distance from the probe centre (1 keeps it, 0.5 halves it)"
        )


def reference_point(points: np.ndarray) -> np.ndarray:
    """(3,) the point whose horizontal distance the factor scales: the centre of the bounding box."""
    pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return 0.5 * (pts.min(axis=0) + pts.max(axis=0))


def _rz(degrees: float) -> np.ndarray:
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _horizontal(v: np.ndarray) -> np.ndarray:
    return np.array([v[0], v[1], 0.0])


def move_matrix(center: np.ndarray, reference: np.ndarray, move: Move) -> np.ndarray:
    """(4, 4) world transform of the move: p -> c + Rz (p - c) + (s - 1) Rz h, h the horizontal
    offset of `reference` from c. The reference lands at distance s |h|, turned by yaw."""
    check_move(move)
    c = np.asarray(center, dtype=np.float64)
    rot = _rz(move.yaw)
    h = _horizontal(np.asarray(reference, dtype=np.float64) - c)
    m = np.eye(4)
    m[:3, :3] = rot
    m[:3, 3] = c - rot @ c + (move.distance_scale - 1.0) * (rot @ h)
    return m


def apply(matrix: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Points (..., 3) transformed by the affine (4, 4) matrix."""
    p = np.asarray(points, dtype=np.float64)
    return p @ matrix[:3, :3].T + matrix[:3, 3]


def elevation(center: np.ndarray, point: np.ndarray) -> float:
    """Degrees above the horizon of `point` seen from `center`."""
    d = np.asarray(point, dtype=np.float64) - np.asarray(center, dtype=np.float64)
    return math.degrees(math.atan2(d[2], math.hypot(d[0], d[1])))


def elevation_change(center: np.ndarray, reference: np.ndarray, move: Move) -> float:
    """Degrees by which the move changes the elevation the object is seen at (negative: seen
    more from above). Zero for a pure yaw; its size says how far the view of the object's sides
    departs from the photograph's."""
    new = apply(move_matrix(center, reference, move), reference)
    return elevation(center, new) - elevation(center, reference)


def move_between(center: np.ndarray, reference: np.ndarray, before: np.ndarray, after: np.ndarray) -> Move:
    """The Move that takes an object placed by the (4, 4) world matrix `before` to `after`, or a
    DimredError saying which part of the change the fixed-view constraint forbids.

    `reference` is the object's reference point (world) at `before`."""
    before, after = np.asarray(before, dtype=np.float64), np.asarray(after, dtype=np.float64)
    delta = after @ np.linalg.inv(before)
    linear = delta[:3, :3]
    stretch = np.linalg.svd(linear, compute_uv=False)
    if np.abs(stretch - 1.0).max() > 1e-3:
        raise DimredError(
            f"the move scales the object (by {stretch.min():.3f}..{stretch.max():.3f}): a real object keeps its size"
        )
    tilt = math.degrees(math.acos(float(np.clip(linear[2, 2], -1.0, 1.0))))
    if tilt > _TOLERANCE_DEG or np.linalg.det(linear) < 0.0:
        raise DimredError(
            f"the move tilts the object by {tilt:.1f} degrees: the panorama shows it from one side only, so it may "
            "only turn about the vertical axis"
        )
    turn = math.degrees(math.atan2(linear[1, 0], linear[0, 0]))
    c = np.asarray(center, dtype=np.float64)
    ref = np.asarray(reference, dtype=np.float64)
    new_ref = apply(delta, ref)
    offset_before, offset_after = _horizontal(ref - c), _horizontal(new_ref - c)
    radius_before, radius_after = float(np.linalg.norm(offset_before)), float(np.linalg.norm(offset_after))
    scale_len = max(radius_before, float(np.linalg.norm(ref - c)), 1e-9)
    lift = float(new_ref[2] - ref[2])
    if abs(lift) > _TOLERANCE_REL * scale_len:
        raise DimredError(
            f"the move lifts the object by {lift:+.3f} (scene units): it must stay on its support plane, "
            "at the height it was photographed at"
        )
    if radius_before <= _TOLERANCE_REL * scale_len:
        raise DimredError("the object stands on the probe centre's vertical axis: no distance to scale or orbit about")
    if radius_after <= _TOLERANCE_REL * scale_len:
        raise DimredError("the move puts the object on the probe centre's vertical axis (distance factor 0)")
    orbit = math.degrees(math.atan2(offset_before[0] * offset_after[1] - offset_before[1] * offset_after[0],
                                    offset_before @ offset_after))
    if abs((turn - orbit + 180.0) % 360.0 - 180.0) > _TOLERANCE_DEG:
        raise DimredError(
            f"the object turns by {round(turn, 1) + 0.0} degrees but goes round the probe centre by "
            f"{round(orbit, 1) + 0.0}: under the "
            "fixed-view constraint both are the same angle, so the photographed side keeps facing the probe"
        )
    return Move(yaw=orbit, distance_scale=radius_after / radius_before)
