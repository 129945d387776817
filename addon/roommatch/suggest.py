"""A suggestion from the photograph: the floor polygon of a room with right-angled walls, for
the artist to accept or correct.

Classical, no learned model: the floor-wall boundary is traced round the panorama as the path,
one row per column below the horizon, that follows the strongest change of log-luminance
while staying smooth (dynamic programming); taken down to the floor at unit camera height it
is the room's outline as the camera sees it. The walls' two directions are the dominant
direction of that outline folded to a quarter turn; each run of outline along one direction
is a wall, its line placed by the median of its points; corners are where consecutive walls
cross. Where too little of the outline is straight, it says so and suggests nothing.
"""
from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .clicks import RoomClicks
from .photo_edges import log_luminance
from .polygon import contains, crossing_edges
from .projection import click_directions, project

_WIDTH = 512  # the boundary is traced at this width
_TOP = np.radians(3.0)  # the boundary is looked for from this far below the horizon ...
_BOTTOM = np.radians(60.0)  # ... down to this far
_JUMP = 3  # rows the path may move from one column to the next
_SMOOTH = 0.02  # cost (log-luminance change) of a row of movement
_AXIS_TOLERANCE = np.radians(12.0)  # outline within this of an axis belongs to a wall along it
_MIN_WALL = 12  # columns of outline that make a wall
_SPAN = 6  # columns either side a direction along the outline is taken over
_MIN_WALLS = 4
_MIN_SHARE = 0.5  # of the columns that must lie on walls


@dataclass(frozen=True)
class Suggestion:
    """The suggested clicks (None when nothing was found), what was found or why not, and the
    traced boundary row per column of the traced width (NaN where it was not followed)."""

    clicks: RoomClicks | None
    message: str
    boundary: np.ndarray


def suggest_room(panorama: np.ndarray, *, width: int, height: int, rotation: np.ndarray | None = None) -> Suggestion:
    """Suggest the floor's corners of `panorama` (H, W, 3) linear RGB as clicks on a `width` x
    `height` panorama (the size the artist clicks on)."""
    log = log_luminance(panorama, _WIDTH)
    rows, cols = log.shape
    top = int(rows / 2 + _TOP / np.pi * rows)
    bottom = int(rows / 2 + _BOTTOM / np.pi * rows)
    change = np.abs(log[top + 1:bottom + 1] - log[top - 1:bottom - 1]) / 2.0
    path = top + _trace(change)
    points = np.stack([np.arange(cols, dtype=np.float64), path.astype(np.float64)], axis=1)
    d = click_directions(points, cols, rows, rotation)
    q = d[:, :2] / -d[:, 2:3]
    walls = _walls(q)
    nothing = Suggestion(None, "", path.astype(np.float64))
    if walls is None or len(walls) < _MIN_WALLS:
        return _nothing(nothing, "the floor-wall boundary it traced has no four straight walls at right angles")
    corners = np.array([_cross(walls[i - 1], walls[i]) for i in range(len(walls))])
    if crossing_edges(corners) is not None or not contains(corners, np.zeros(2)):
        return _nothing(nothing, "the walls it found do not close round the camera")
    floor = project(np.concatenate([corners, -np.ones((len(corners), 1))], axis=1), width, height, rotation)
    clicks = RoomClicks(width, height, tuple(map(tuple, floor.tolist())), manhattan=True)
    return Suggestion(clicks, f"suggested {len(corners)} floor corners from the photograph's lines",
                      path.astype(np.float64))


def _nothing(empty: Suggestion, why: str) -> Suggestion:
    return Suggestion(None, f"no room suggested: {why}; click the floor's corners", empty.boundary)


def _trace(change: np.ndarray) -> np.ndarray:
    """The row (within `change`, (r, w)) per column of the smooth path of greatest change."""
    r, w = change.shape
    score = change[:, 0].copy()
    back = np.zeros((r, w), dtype=np.int64)
    moves = np.arange(-_JUMP, _JUMP + 1)
    rows = np.arange(r)
    for c in range(1, w):  # one step per column, vectorised over the rows
        source = np.clip(rows[:, None] + moves[None, :], 0, r - 1)
        options = score[source] - _SMOOTH * np.abs(moves)[None, :]
        best = np.argmax(options, axis=1)
        back[:, c] = source[rows, best]
        score = options[rows, best] + change[:, c]
    path = np.empty(w, dtype=np.int64)
    path[-1] = int(np.argmax(score))
    for c in range(w - 1, 0, -1):
        path[c - 1] = back[path[c], c]
    return path


def _walls(q: np.ndarray) -> list[tuple[np.ndarray, float]] | None:
    """Walls (unit normal, offset) along the traced outline `q` (n, 2), in order, alternating
    between the outline's two dominant directions; None when too little of it is straight."""
    # Directions over a few columns: the traced rows are whole pixels.
    step = np.roll(q, -_SPAN, axis=0) - np.roll(q, _SPAN, axis=0)
    angle = np.arctan2(step[:, 1], step[:, 0])
    weight = 1.0 / (1.0 + np.sum(q * q, axis=1))  # near outline is the better placed
    turn = np.arctan2(np.sum(weight * np.sin(4 * angle)), np.sum(weight * np.cos(4 * angle))) / 4.0
    folded = np.mod(angle - turn + np.pi / 4, np.pi / 2) - np.pi / 4
    axis = np.where(np.abs(folded) <= _AXIS_TOLERANCE,
                    np.mod(np.round((angle - turn) / (np.pi / 2)), 2).astype(np.int64), -1)
    if np.mean(axis >= 0) < _MIN_SHARE:
        return None
    # Runs of one axis round the panorama, starting after a change so no run wraps.
    change = np.flatnonzero(axis != np.roll(axis, 1))
    if change.size == 0:
        return None
    start = change[0]
    axis, q = np.roll(axis, -start), np.roll(q, -start, axis=0)
    bounds = np.concatenate([np.flatnonzero(axis != np.roll(axis, 1)), [len(axis)]])
    units = np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    walls: list[tuple[int, float, int]] = []
    for a, b in itertools.pairwise(bounds):
        k = axis[a]
        if k < 0 or b - a < _MIN_WALL:
            continue
        normal = units[1 - k]
        offset = float(np.median(q[a:b] @ normal))
        if walls and walls[-1][0] == k:
            # The same direction again: a wall broken by clutter (keep the longer run's line).
            if b - a > walls[-1][2]:
                walls[-1] = (k, offset, b - a)
            continue
        walls.append((k, offset, b - a))
    if len(walls) > 1 and walls[0][0] == walls[-1][0]:
        first, last = walls[0], walls.pop()
        walls[0] = first if first[2] >= last[2] else last
    return [(units[1 - k], offset) for k, offset, _ in walls]


def _cross(a: tuple[np.ndarray, float], b: tuple[np.ndarray, float]) -> np.ndarray:
    return np.linalg.solve(np.array([a[0], b[0]]), np.array([a[1], b[1]]))
