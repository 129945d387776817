"""The matched room as meshes (Floor, Walls, Ceiling) and as the edges a picture draws.

Every face's normal points into the room, towards the probe centre: the floor's up, the
ceiling's down, each wall's inwards.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import polygon
from .fit import RoomFit

NAMES = ("Floor", "Walls", "Ceiling")


@dataclass(frozen=True)
class MeshData:
    """Vertices (v, 3) in metres and faces as tuples of vertex indices."""

    name: str
    vertices: np.ndarray
    faces: tuple[tuple[int, ...], ...]


def room_meshes(room: RoomFit) -> tuple[MeshData, MeshData, MeshData]:
    """Floor, Walls and Ceiling of `room`, named as in NAMES."""
    corners = _counter_clockwise(room.corners)
    n = len(corners)
    floor = np.concatenate([corners, np.zeros((n, 1))], axis=1)
    ceiling = np.concatenate([corners, np.full((n, 1), room.ceiling_height)], axis=1)
    ring = tuple(range(n))
    # Wall i: bottom i, top i, top i + 1, bottom i + 1 turns its normal to the polygon's inside.
    walls = tuple((i, n + i, n + (i + 1) % n, (i + 1) % n) for i in range(n))
    return (MeshData("Floor", floor, (ring,)),
            MeshData("Walls", np.concatenate([floor, ceiling]), walls),
            MeshData("Ceiling", ceiling, (tuple(reversed(ring)),)))


def room_edges(room: RoomFit) -> np.ndarray:
    """(3n, 2, 3) every edge of the room's proxies: floor edges, ceiling edges, wall corners."""
    c = room.corners
    n = len(c)
    bottom = np.concatenate([c, np.zeros((n, 1))], axis=1)
    top = np.concatenate([c, np.full((n, 1), room.ceiling_height)], axis=1)
    return np.concatenate([np.stack([bottom, np.roll(bottom, -1, axis=0)], axis=1),
                           np.stack([top, np.roll(top, -1, axis=0)], axis=1),
                           np.stack([bottom, top], axis=1)])


def _counter_clockwise(corners: np.ndarray) -> np.ndarray:
    return corners if polygon.signed_area(corners) > 0.0 else corners[::-1]
