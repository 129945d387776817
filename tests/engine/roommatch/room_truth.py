"""Rooms of known geometry as clicks: corners projected to panorama pixels (a user's clicks are
whole pixels), for the engine tests and the ground truth against renders."""
from __future__ import annotations

import numpy as np

from addon.roommatch.projection import project


def clicks_of(points: np.ndarray, probe: np.ndarray, width: int, height: int,
              rotation: np.ndarray | None = None, *, rounded: bool = True) -> np.ndarray:
    """(n, 2) pixel clicks (x, y) on the world points (n, 3) seen from `probe` (3,)."""
    xy = project(np.asarray(points, dtype=np.float64) - probe, width, height, rotation)
    return np.round(xy) if rounded else xy


def floor_points(corners: np.ndarray) -> np.ndarray:
    c = np.asarray(corners, dtype=np.float64)
    return np.concatenate([c, np.zeros((len(c), 1))], axis=1)


def rotation_z(degrees: float) -> np.ndarray:
    a = np.radians(degrees)
    return np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])


def distance_errors(found: np.ndarray, truth: np.ndarray, probe: np.ndarray) -> np.ndarray:
    """Each corner's error in metres per metre of its horizontal distance from the probe."""
    return np.linalg.norm(found - truth, axis=1) / np.linalg.norm(truth - probe[:2], axis=1)


def flat_panorama(corners: np.ndarray, ceiling: float, probe: np.ndarray, width: int, height: int) -> np.ndarray:
    """(H, W, 3) a panorama of the room seen from `probe`, each surface one flat grey (walls
    alternating), its edges where the room's are: a render without light."""
    from addon.geometry.latlong import pixel_directions
    from addon.roommatch.polygon import ray_hit

    d = pixel_directions(width, height)
    c = np.asarray(corners, dtype=np.float64) - probe[:2]
    azimuth = d[0, :, :2] / np.linalg.norm(d[0, :, :2], axis=1, keepdims=True)
    reach = np.array([ray_hit(c, a) for a in azimuth])  # one ray per column
    wall = np.array([_wall_hit(c, a, r) for a, r in zip(azimuth, reach, strict=True)])
    across = np.linalg.norm(d[..., :2], axis=-1)
    z = probe[2] + reach[None, :] * d[..., 2] / np.maximum(across, 1e-12)
    grey = np.where(z < 0.0, 0.2, np.where(z > ceiling, 0.9, np.where(wall[None, :] % 2 == 0, 0.5, 0.6)))
    return np.repeat(grey[..., None], 3, axis=2).astype(np.float32)


def _wall_hit(c: np.ndarray, a: np.ndarray, reach: float) -> int:
    e = np.roll(c, -1, axis=0) - c
    p = a * reach
    t = np.sum((p - c) * e, axis=1) / np.sum(e * e, axis=1)
    gap = np.linalg.norm(c + np.clip(t, 0, 1)[:, None] * e - p, axis=1)
    return int(np.argmin(gap))


def with_box(panorama: np.ndarray, params: np.ndarray, camera: float, colour: tuple[float, float, float]) -> np.ndarray:
    """`panorama` with a box (`object_box.silhouette`'s parameters) painted flat in `colour`."""
    from addon.geometry.latlong import pixel_directions
    from addon.roommatch.object_box import silhouette

    height, width = panorama.shape[:2]
    out = panorama.copy()
    out[silhouette(np.asarray(params, dtype=np.float64), pixel_directions(width, height), camera)] = colour
    return out
