"""Clicks moved onto the photograph: each floor edge's wall-floor boundary found in the panorama.

A click is good to a pixel or so; the boundary between a wall and the floor, seen along a whole
wall, is good to a fraction of one. Along each floor edge of the room fitted to the clicks, the
photograph's edge is looked for across the edge's reprojection (`photo_edges.edge_samples`); the
points found, taken down to the floor, are fitted by a line (weighted by how precisely a pixel
places a floor point at that distance, robust to clutter in front of the wall), and each corner
becomes the crossing of its two walls' lines. Edges where the photograph shows too little keep
their clicked corners. The result is new clicks, so the fit (and Manhattan snapping) runs on
them as on the artist's; a corner the lines would move farther than a click errs keeps its click.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from .clicks import RoomClicks
from .fit import RoomFit
from .photo_edges import edge_samples, log_luminance
from .projection import click_directions, pixel_offsets, project

# How far the photograph's edge is looked for, round by round, in pixels of the clicks (a click
# is good to a pixel or two; farther, a window's frame or a skirting board would be taken).
_SEARCHES = (3.0, 2.0, 1.5)
_MAX_MOVE = 2.5  # pixels of the clicks a refined corner may move from its click
_MIN_SHOWN = 0.3  # share of an edge's samples that must find the photograph's edge
_MIN_POINTS = 12
_MIN_ANGLE = np.radians(10.0)  # walls closer to parallel than this do not make a corner
_ROBUST = 3.0  # Tukey's constant, in pixels of reprojection


def refine_clicks(panorama: np.ndarray, clicks: RoomClicks, room: RoomFit, *, rotation: np.ndarray | None = None,
                  max_width: int = 2048) -> tuple[RoomClicks, np.ndarray]:
    """The floor clicks moved onto the photograph's wall-floor edges near `room` (fitted to
    `clicks`), and which floor edges (n,) the photograph showed."""
    width = min(max_width, int(np.asarray(panorama).shape[1]) // 2 * 2)
    log = log_luminance(panorama, width)
    unit = (room.corners - room.probe[:2]) / room.camera_height
    shown = np.zeros(len(unit), dtype=bool)
    for search in np.array(_SEARCHES) * max(1.0, width / clicks.width):
        lines = [_wall_line(log, a, b, rotation, search) for a, b in zip(unit, np.roll(unit, -1, axis=0), strict=True)]
        shown = np.array([line is not None for line in lines])
        unit = np.array([_corner(unit[i], lines[i - 1], lines[i]) for i in range(len(unit))])
    floor = project(np.concatenate([unit, -np.ones((len(unit), 1))], axis=1), clicks.width, clicks.height, rotation)
    clicked = np.asarray(clicks.floor, dtype=np.float64)
    # A corner the walls' lines put farther from its click than a click errs stays where it was
    # clicked: a wall seen at a grazing angle places a crossing poorly.
    far = np.linalg.norm(pixel_offsets(floor, clicked, clicks.width), axis=1) > _MAX_MOVE
    floor[far] = clicked[far]
    return dataclasses.replace(clicks, floor=tuple(map(tuple, floor.tolist()))), shown


def _wall_line(log: np.ndarray, a: np.ndarray, b: np.ndarray, rotation: np.ndarray | None,
               search: float) -> tuple[np.ndarray, float] | None:
    """The wall's floor line (unit normal n, offset c: n . q = c) at unit camera height, or None."""
    height, width = log.shape
    samples = edge_samples(log, np.append(a, -1.0), np.append(b, -1.0), rotation, search)
    found = samples.found()
    if len(found) < max(_MIN_POINTS, _MIN_SHOWN * len(samples.offsets)):
        return None
    d = click_directions(found, width, height, rotation)
    below = d[:, 2] < -1e-3
    q = d[below, :2] / -d[below, 2:3]
    # A pixel moves a floor point at distance r by about (1 + r^2) times the pixel's angle.
    scale = (1.0 + np.sum(q * q, axis=1)) * (2.0 * np.pi / width)
    weight = 1.0 / scale**2
    w = weight
    for _ in range(8):  # weighted total least squares, then re-weighted robustly about the line found
        if np.count_nonzero(w) < _MIN_POINTS:
            return None
        centre = (w @ q) / w.sum()
        spread = (q - centre).T @ ((q - centre) * w[:, None])
        normal = np.linalg.eigh(spread)[1][:, 0]
        offset = float(normal @ centre)
        residual = (q @ normal - offset) / scale
        w = weight * np.where(np.abs(residual) < _ROBUST, (1.0 - (residual / _ROBUST) ** 2) ** 2, 0.0)
    return normal, offset


def _corner(old: np.ndarray, before: tuple[np.ndarray, float] | None,
            after: tuple[np.ndarray, float] | None) -> np.ndarray:
    """The crossing of the two walls' lines; with one line, the old corner moved onto it."""
    if before is not None and after is not None:
        m = np.array([before[0], after[0]])
        if abs(np.linalg.det(m)) > np.sin(_MIN_ANGLE):
            return np.linalg.solve(m, [before[1], after[1]])
    for line in (before, after):
        if line is not None:
            normal, offset = line
            return old - (normal @ old - offset) * normal
    return old
