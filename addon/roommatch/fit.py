"""From clicks to the room: the floor polygon, the camera height, the ceiling.

Seen from the probe centre c, a floor corner clicked along the unit direction d (d_z < 0) lies
at c + d h / (-d_z) for camera height h: at unit height its offset from the probe is
q = d_xy / (-d_z), and every length in the room is h times its unit-height length. So the
polygon's shape comes from the clicks alone (and from Manhattan snapping), its scale from the
camera height or from one known length. The room's floor is at z = 0 and the probe centre at
(x, y, h) for the given `origin` (x, y).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import DimredError
from . import manhattan, polygon
from .clicks import RoomClicks
from .projection import click_directions, pixel_offsets, project

DEFAULT_CEILING_HEIGHT = 2.5  # metres above the floor, where no wall-ceiling point is clicked
# A floor corner must be seen at least this far below the horizon: at 0.5 degrees a corner
# 1.6 m below the camera is 180 m away, and a pixel's error moves it by tens of metres.
_MIN_DEPRESSION = np.radians(0.5)


@dataclass(frozen=True)
class RoomFit:
    """The matched room: floor corners (n, 2) in metres in click order, the floor at z = 0, the
    ceiling at `ceiling_height`, the probe centre (3,), and how far (pixels) each corner's
    reprojection lies from its click and each floor edge's worst end."""

    corners: np.ndarray
    ceiling_height: float
    probe: np.ndarray
    camera_height: float
    corner_errors: np.ndarray
    scale_source: str
    manhattan_turn: float | None  # degrees of the walls' axes from +X, when snapped
    ceiling_from_click: bool

    @property
    def edge_errors(self) -> np.ndarray:
        """(n,) the larger reprojection error of floor edge i's two ends (corner i to i + 1)."""
        return np.maximum(self.corner_errors, np.roll(self.corner_errors, -1))

    def wall_lengths(self) -> np.ndarray:
        return np.linalg.norm(np.roll(self.corners, -1, axis=0) - self.corners, axis=1)

    def summary(self) -> dict[str, Any]:
        return {
            "corners_m": np.round(self.corners, 4).tolist(),
            "camera_height_m": round(self.camera_height, 4),
            "ceiling_height_m": round(self.ceiling_height, 4),
            "ceiling_from": "click" if self.ceiling_from_click else "default",
            "probe_center": np.round(self.probe, 4).tolist(),
            "scale_from": self.scale_source,
            "manhattan_turn_deg": None if self.manhattan_turn is None else round(self.manhattan_turn, 3),
            "wall_lengths_m": np.round(self.wall_lengths(), 4).tolist(),
            "corner_error_px": np.round(self.corner_errors, 3).tolist(),
            "edge_error_px": np.round(self.edge_errors, 3).tolist(),
        }


def fit_room(clicks: RoomClicks, *, rotation: np.ndarray | None = None, origin: tuple[float, float] = (0.0, 0.0),
             ceiling_height: float = DEFAULT_CEILING_HEIGHT) -> RoomFit:
    """The room the clicks show; DimredError, naming the click, when they show none.

    `rotation` is the world's Mapping rotation M (a world direction d samples the panorama at
    M d); `ceiling_height` is used where no wall-ceiling point was clicked.
    """
    w, h = clicks.width, clicks.height
    floor = np.asarray(clicks.floor, dtype=np.float64)
    unit = unit_floor_points(floor, w, h, rotation, [f"floor corner {i}" for i in range(len(floor))])
    check_simple(unit, "the clicked floor polygon")
    turn = None
    if clicks.manhattan:
        snapped = manhattan.snap(unit, floor, w, h, rotation)
        unit, turn = snapped.corners, float(np.degrees(snapped.turn))
        check_simple(unit, "the floor polygon snapped to right angles")
    if not polygon.contains(unit, np.zeros(2)):
        raise DimredError("the probe centre lies outside the clicked floor polygon: click the corners of the room "
                          "the panorama was taken in, in order round it")
    camera = _camera_height(clicks, unit, rotation)
    ceiling, from_click = _ceiling_height(clicks, unit, camera, rotation, ceiling_height)
    points = np.concatenate([unit, -np.ones((len(unit), 1))], axis=1)
    errors = np.linalg.norm(pixel_offsets(project(points, w, h, rotation), floor, w), axis=1)
    return RoomFit(corners=unit * camera + np.asarray(origin, dtype=np.float64), ceiling_height=ceiling,
                   probe=np.array([origin[0], origin[1], camera], dtype=np.float64), camera_height=camera,
                   corner_errors=errors, scale_source=clicks.scale_source, manhattan_turn=turn,
                   ceiling_from_click=from_click)


def unit_floor_points(points: np.ndarray, width: int, height: int, rotation: np.ndarray | None,
                       names: list[str]) -> np.ndarray:
    """(n, 2) floor points at unit camera height seen at the clicks `points` (n, 2)."""
    d = click_directions(points, width, height, rotation)
    high = np.flatnonzero(d[:, 2] > -np.sin(_MIN_DEPRESSION))
    if high.size:
        i = int(high[0])
        x, y = points[i]
        raise DimredError(f"{names[i]} ({x:g}, {y:g}) is not below the horizon, so its ray never meets the floor: "
                          f"floor points lie below row {height / 2 - 0.5:g} (by 0.5° at least)")
    return d[:, :2] / -d[:, 2:3]


def check_simple(unit: np.ndarray, what: str, *, hint: str = "click the corners in order round the room") -> None:
    """DimredError naming two edges of the polygon `unit` (n, 2) that cross, if any."""
    crossing = polygon.crossing_edges(unit)
    if crossing is not None:
        i, j = crossing
        n = len(unit)
        raise DimredError(f"{what} crosses itself (edge {i}-{(i + 1) % n} meets edge {j}-{(j + 1) % n}): {hint}")


def _camera_height(clicks: RoomClicks, unit: np.ndarray, rotation: np.ndarray | None) -> float:
    """The camera height in metres: given, or the known length over its unit-height length."""
    length = clicks.known_length
    if length is None:
        return clicks.height_or_default()
    if length.kind == "wall":
        i = length.edge
        unit_length = float(np.linalg.norm(unit[(i + 1) % len(unit)] - unit[i]))
    else:
        ends = np.array([length.start, length.end], dtype=np.float64)
        if length.kind == "floor":
            q = unit_floor_points(ends, clicks.width, clicks.height, rotation,
                                   ["the known length's start", "the known length's end"])
            unit_length = float(np.linalg.norm(q[1] - q[0]))
        else:
            foot = unit_floor_points(ends[:1], clicks.width, clicks.height, rotation, ["the known length's start"])
            top = click_directions(ends[1], clicks.width, clicks.height, rotation)
            # Straight above the foot, at its horizontal distance from the probe.
            unit_length = 1.0 + float(np.linalg.norm(foot)) * top[2] / max(float(np.linalg.norm(top[:2])), 1e-12)
    if not unit_length > 1e-9:
        raise DimredError(f"the known {length.kind} length's clicks give it no length: click its two ends apart"
                          + (" (its top above its foot)" if length.kind == "vertical" else ""))
    return length.metres / unit_length


def _ceiling_height(clicks: RoomClicks, unit: np.ndarray, camera: float, rotation: np.ndarray | None,
                    default: float) -> tuple[float, bool]:
    if clicks.ceiling is None:
        if not default > camera:
            raise DimredError(f"the ceiling height {default:g} m is not above the camera ({camera:.3g} m): "
                              "give a higher ceiling or click where a wall meets the ceiling")
        return default, False
    x, y = clicks.ceiling
    d = click_directions(np.array(clicks.ceiling), clicks.width, clicks.height, rotation)
    if d[2] < np.sin(_MIN_DEPRESSION):
        raise DimredError(f"the ceiling point ({x:g}, {y:g}) is not above the horizon: click where a wall meets "
                          f"the ceiling, above row {clicks.height / 2 - 0.5:g}")
    across = float(np.linalg.norm(d[:2]))
    reach = polygon.ray_hit(unit, d[:2] / across)
    if reach is None:
        raise DimredError(f"the ceiling point ({x:g}, {y:g}) looks past every wall of the floor polygon")
    return camera * (1.0 + reach * d[2] / across), True
