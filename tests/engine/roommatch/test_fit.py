"""Clicks to the room's geometry, from arrays: exact clicks give the room back, whole-pixel
clicks within the issue's bounds, and the scale comes from the height or one known length."""
from __future__ import annotations

import numpy as np
import pytest

from addon.roommatch.clicks import KnownLength, RoomClicks
from addon.roommatch.fit import fit_room
from addon.roommatch.meshes import room_edges, room_meshes
from addon.roommatch.polygon import signed_area
from tests.engine.roommatch.room_truth import clicks_of, distance_errors, floor_points, rotation_z

W, H = 1024, 512
L_ROOM = np.array([(-2.0, -1.6), (3.4, -1.6), (3.4, 0.9), (1.2, 0.9), (1.2, 2.8), (-2.0, 2.8)])
PROBE = np.array([0.3, -0.2, 1.55])


def _clicks(corners=L_ROOM, probe=PROBE, rotation=None, rounded=True, **options) -> RoomClicks:
    floor = clicks_of(floor_points(corners), probe, W, H, rotation, rounded=rounded)
    return RoomClicks(W, H, tuple(map(tuple, floor)), **options)


def test_exact_clicks_give_the_room_back() -> None:
    room = fit_room(_clicks(rounded=False, camera_height=1.55), origin=(0.3, -0.2))
    assert np.allclose(room.corners, L_ROOM, atol=1e-9)
    assert np.allclose(room.probe, PROBE)
    assert room.corner_errors.max() < 1e-6


def test_whole_pixel_clicks_within_a_centimetre_per_metre() -> None:
    room = fit_room(_clicks(camera_height=1.55), origin=(0.3, -0.2))
    assert distance_errors(room.corners, L_ROOM, PROBE).max() < 0.01


def test_a_world_rotation_turns_the_clicks_not_the_room() -> None:
    rotation = rotation_z(40.0)
    room = fit_room(_clicks(rotation=rotation, rounded=False, camera_height=1.55), rotation=rotation,
                    origin=(0.3, -0.2))
    assert np.allclose(room.corners, L_ROOM, atol=1e-9)


@pytest.mark.parametrize("length", [
    KnownLength("wall", 5.4, edge=0),
    KnownLength("vertical", 2.0, start=(0.0, 0.0), end=(0.0, 0.0)),
    KnownLength("floor", 3.2, start=(0.0, 0.0), end=(0.0, 0.0)),
])
def test_a_known_length_gives_the_camera_height(length: KnownLength) -> None:
    if length.kind == "vertical":  # a door frame's edge on the west wall, 2 m high
        ends = clicks_of(np.array([[-2.0, 2.0, 0.0], [-2.0, 2.0, 2.0]]), PROBE, W, H)
    elif length.kind == "floor":  # along the south wall, 3.2 m apart
        ends = clicks_of(np.array([[-1.5, -1.6, 0.0], [1.7, -1.6, 0.0]]), PROBE, W, H)
    if length.kind != "wall":
        length = KnownLength(length.kind, length.metres, start=tuple(ends[0]), end=tuple(ends[1]))
    room = fit_room(_clicks(known_length=length), origin=(0.3, -0.2))
    assert room.camera_height == pytest.approx(1.55, rel=0.02)
    assert distance_errors(room.corners, L_ROOM, PROBE).max() < 0.02


def test_manhattan_snapping_squares_a_turned_room_and_finds_its_turn() -> None:
    turn = np.radians(25.0)
    box = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
    corners = box @ np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    probe = np.array([0.0, 0.0, 1.5])
    room = fit_room(_clicks(corners, probe, camera_height=1.5, manhattan=True))
    assert room.manhattan_turn == pytest.approx(25.0 - 90.0 * round(25.0 / 90.0), abs=0.3)
    edges = np.roll(room.corners, -1, axis=0) - room.corners
    cosines = np.sum(edges * np.roll(edges, -1, axis=0), axis=1) / np.prod(
        np.linalg.norm([edges, np.roll(edges, -1, axis=0)], axis=2), axis=0)
    assert np.abs(cosines).max() < 1e-9
    assert distance_errors(room.corners, corners, probe).max() < 0.01
    assert room.corner_errors.max() < 1.0  # pixels: the snapped corners still sit on the clicks


def test_a_wall_ceiling_click_gives_the_ceiling_height() -> None:
    ceiling = clicks_of(np.array([[3.4, -0.5, 2.6]]), PROBE, W, H, rounded=False)[0]
    room = fit_room(_clicks(rounded=False, camera_height=1.55, ceiling=tuple(ceiling)), origin=(0.3, -0.2))
    assert room.ceiling_from_click
    assert room.ceiling_height == pytest.approx(2.6, abs=1e-9)


def test_meshes_face_into_the_room() -> None:
    room = fit_room(_clicks(rounded=False, camera_height=1.55), origin=(0.3, -0.2))
    floor, walls, ceiling = room_meshes(room)
    assert signed_area(floor.vertices[list(floor.faces[0]), :2]) > 0  # counter-clockwise: normal up
    assert signed_area(ceiling.vertices[list(ceiling.faces[0]), :2]) < 0  # normal down
    for face in walls.faces:
        a, b, c = walls.vertices[list(face[:3])]
        normal = np.cross(b - a, c - a)
        assert np.dot(normal, PROBE - a) > 0  # towards the probe centre (inside this room)
    assert room_edges(room).shape == (18, 2, 3)
