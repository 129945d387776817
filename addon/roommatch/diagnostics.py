"""room_diagnostics.png: the whole panorama with every edge of the matched room drawn over it.

Floor edges green, ceiling edges magenta, the walls' vertical corners cyan, object boxes orange,
each curve where it reprojects in lat-long; the clicks as yellow crosses. A wall in the wrong place shows as a line
beside the photograph's.
"""
from __future__ import annotations

import numpy as np

from ..geometry.resample import resample_axis
from ..segmentation.diagnostics import _srgb, _tone_map
from .clicks import RoomClicks
from .fit import RoomFit
from .hull import Hull
from .meshes import room_edges
from .projection import project
from .solids import Solid

# Floor, ceiling, wall corner, object box.
_COLOURS = np.array([[0.1, 1.0, 0.2], [1.0, 0.2, 1.0], [0.0, 1.0, 1.0], [1.0, 0.55, 0.0]], dtype=np.float32)
# A box's 12 edges between its corners (the bottom four, then the top four).
_BOX_EDGES = np.array([(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)])
_CLICK = np.array([1.0, 0.9, 0.0], dtype=np.float32)
_SAMPLES = 4000  # along one edge at most: under half a pixel apart at 2048 wide


def room_picture(panorama: np.ndarray, room: RoomFit, clicks: RoomClicks | None = None, *,
                 boxes: tuple[np.ndarray, ...] = (), solids: tuple[Solid | Hull, ...] = (),
                 rotation: np.ndarray | None = None, max_width: int = 2048) -> np.ndarray:
    """(h, w, 3) uint8 sRGB picture of `panorama` (H, W, 3) linear RGB, top row first, reduced
    to at most `max_width` wide, with `room`'s edges, the `boxes` ((8, 3) world corners each),
    the object proxies `solids` and the `clicks` drawn."""
    image = np.asarray(panorama, dtype=np.float32)
    height, width = image.shape[:2]
    if width > max_width:
        height, width = max(1, round(height * max_width / width)), max_width
        image = resample_axis(resample_axis(image, height, axis=0), width, axis=1)
    picture = _tone_map(image)
    walls = room_edges(room)
    objects = [np.asarray(corners, dtype=np.float64)[_BOX_EDGES] for corners in boxes]
    objects += [solid.edges() for solid in solids]
    edges = np.concatenate([walls, *objects]) - room.probe
    kind = np.concatenate([np.repeat(np.arange(3), len(walls) // 3), np.full(len(edges) - len(walls), 3)])
    # Each edge sampled under half a pixel apart: a carved proxy's many short edges take few samples.
    ends = edges / np.maximum(np.linalg.norm(edges, axis=2, keepdims=True), 1e-12)
    angle = np.arccos(np.clip(np.einsum("ij,ij->i", ends[:, 0], ends[:, 1]), -1.0, 1.0))
    count = np.clip(np.ceil(angle * width / np.pi).astype(np.int64) + 2, 2, _SAMPLES)
    edge = np.repeat(np.arange(len(edges)), count)
    t = ((np.arange(len(edge)) - np.repeat(np.cumsum(count) - count, count)) / (count[edge] - 1))[:, None]
    points = edges[edge, 0] + t * (edges[edge, 1] - edges[edge, 0])
    _stamp(picture, project(points, width, height, rotation), _COLOURS[kind[edge]], radius=1)
    if clicks is not None:
        scale = np.array([width / clicks.width, height / clicks.height])
        named = [*clicks.floor, *([clicks.ceiling] if clicks.ceiling is not None else [])]
        marks = (np.asarray(named, dtype=np.float64) + 0.5) * scale - 0.5
        arms = np.arange(-4, 5)
        cross = np.concatenate([np.stack([arms, arms], 1), np.stack([arms, -arms], 1)])
        stamped = (marks[:, None, :] + cross[None]).reshape(-1, 2)
        _stamp(picture, stamped, np.broadcast_to(_CLICK, (len(stamped), 3)), radius=0)
    return np.round(_srgb(picture) * 255.0).astype(np.uint8)


def _stamp(picture: np.ndarray, xy: np.ndarray, colour: np.ndarray, *, radius: int) -> None:
    """Paint the pixels at `xy` (n, 2) and their neighbours within `radius` (wrapping in x)."""
    height, width = picture.shape[:2]
    col, row = np.round(xy[:, 0]).astype(np.int64), np.round(xy[:, 1]).astype(np.int64)
    for dy in range(-radius, radius + 1):
        for dx in range(-radius, radius + 1):
            r = row + dy
            ok = (r >= 0) & (r < height)
            picture[r[ok], np.mod(col[ok] + dx, width)] = colour[ok]
