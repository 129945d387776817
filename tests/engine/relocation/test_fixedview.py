"""The fixed-view constraint: the panorama shows the object from one side only, so a move may
only turn it about the vertical axis through the probe centre and change its horizontal distance
to the centre, keeping that side facing the probe. The move it allows, and the moves it refuses."""
from __future__ import annotations

import math

import numpy as np
import pytest

from addon.errors import DimredError
from addon.relocation.fixedview import (
    Move,
    apply,
    check_move,
    elevation_change,
    move_between,
    move_matrix,
    reference_point,
)

CENTER = np.array([0.3, -0.2, 1.5])
BOX = np.array([[x, y, z] for x in (1.0, 1.6) for y in (0.8, 1.2) for z in (0.0, 0.5)])


def _view_frame(center: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Rows: the horizontal direction from the centre to the reference, its left, and up."""
    h = reference - center
    h[2] = 0.0
    h /= np.linalg.norm(h)
    return np.array([h, np.cross([0.0, 0.0, 1.0], h), [0.0, 0.0, 1.0]])


@pytest.mark.parametrize("yaw, scale", [(40.0, 1.3), (-75.0, 0.6), (180.0, 1.0), (0.0, 2.0)])
def test_the_same_side_faces_the_probe(yaw, scale):
    ref = reference_point(BOX)
    moved = apply(move_matrix(CENTER, ref, Move(yaw, scale)), BOX)
    new_ref = reference_point(moved)
    # In the frame that looks from the probe at the object, the object is unchanged.
    before = (BOX - ref) @ _view_frame(CENTER, ref).T
    after = (moved - new_ref) @ _view_frame(CENTER, new_ref).T
    np.testing.assert_allclose(after, before, atol=1e-12)
    h0, h1 = (ref - CENTER)[:2], (new_ref - CENTER)[:2]
    assert np.linalg.norm(h1) == pytest.approx(scale * np.linalg.norm(h0))
    assert new_ref[2] == pytest.approx(ref[2])
    assert math.degrees(math.atan2(h1[1], h1[0]) - math.atan2(h0[1], h0[0])) % 360 == pytest.approx(yaw % 360)


def test_elevation_change():
    ref = reference_point(BOX)
    assert elevation_change(CENTER, ref, Move(70.0, 1.0)) == pytest.approx(0.0, abs=1e-12)
    # The object is below the probe: nearer, it is seen more from above.
    nearer = elevation_change(CENTER, ref, Move(0.0, 0.5))
    farther = elevation_change(CENTER, ref, Move(0.0, 2.0))
    assert nearer < 0.0 < farther
    r = np.linalg.norm((ref - CENTER)[:2])
    dz = ref[2] - CENTER[2]
    assert nearer == pytest.approx(math.degrees(math.atan2(dz, 0.5 * r) - math.atan2(dz, r)))


@pytest.mark.parametrize("move", [Move(0.0, 0.0), Move(10.0, -1.3), Move(float("nan"), 1.0),
                                  Move(10.0, float("inf"))])
def test_impossible_requests_are_refused(move):
    with pytest.raises(DimredError, match=r"distance factor|yaw"):
        check_move(move)
    with pytest.raises(DimredError):
        move_matrix(CENTER, reference_point(BOX), move)


def _placed(matrix: np.ndarray) -> np.ndarray:
    before = np.eye(4)
    before[:3, 3] = (1.3, 1.0, 0.25)
    return matrix @ before


def test_move_between_recovers_the_move():
    ref = reference_point(BOX)
    before = _placed(np.eye(4))
    move = Move(-33.0, 1.25)
    got = move_between(CENTER, ref, before, move_matrix(CENTER, ref, move) @ before)
    assert got.yaw == pytest.approx(move.yaw) and got.distance_scale == pytest.approx(move.distance_scale)


def _rotation(axis: str, degrees: float) -> np.ndarray:
    a = math.radians(degrees)
    c, s = math.cos(a), math.sin(a)
    m = np.eye(4)
    i, j = {"x": (1, 2), "y": (2, 0), "z": (0, 1)}[axis]
    m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
    return m


def _about(point: np.ndarray, m: np.ndarray) -> np.ndarray:
    t, back = np.eye(4), np.eye(4)
    t[:3, 3], back[:3, 3] = -point, point
    return back @ m @ t


@pytest.mark.parametrize("case, expected", [
    ("tilt", "tilts the object by 10.0 degrees"),
    ("lift", "lifts the object by +0.200"),
    ("scale", "scales the object"),
    ("turn only", "turns by 30.0 degrees but goes round the probe centre by 0.0"),
    ("slide", "turns by 0.0 degrees but goes round"),
    ("onto the axis", "on the probe centre's vertical axis"),
])
def test_move_between_refuses_what_the_constraint_forbids(case, expected):
    ref = reference_point(BOX)
    before = _placed(np.eye(4))
    lift, onto = np.eye(4), np.eye(4)
    lift[2, 3] = 0.2
    onto[:2, 3] = (CENTER - ref)[:2]
    delta = {
        "tilt": _about(ref, _rotation("x", 10.0)),
        "lift": lift,
        "scale": _about(ref, np.diag([1.2, 1.2, 1.2, 1.0])),
        "turn only": _about(ref, _rotation("z", 30.0)),
        "slide": _about(CENTER, _rotation("z", 30.0)) @ _about(ref, _rotation("z", -30.0)),
        "onto the axis": onto,
    }[case]
    with pytest.raises(DimredError, match=expected.replace("+", r"\+").replace("(", r"\(")):
        move_between(CENTER, ref, before, delta @ before)
