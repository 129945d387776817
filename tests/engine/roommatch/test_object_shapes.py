"""Object from Photo's proxies on flat panoramas: a box stays a box, an armchair-like object (a
seat before a higher back) gets a stepped box, and a footprint of clicked contact points gives a
prism whose fitted height is the object's."""
from __future__ import annotations

import numpy as np
import pytest

from addon.errors import DimredError
from addon.roommatch.clicks import ObjectClicks
from addon.roommatch.object_box import BoxFit
from addon.roommatch.object_shapes import object_from_click, object_from_footprint, object_proxy
from addon.roommatch.projection import project
from tests.engine.roommatch.room_truth import clicks_of, flat_panorama, with_box

ROOM = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
PROBE = np.array([0.0, 0.0, 1.5])
W, H = 1024, 512
TURN = np.radians(20.0)
CHAIR = np.array([1.8, 0.6, np.log(0.8), np.log(0.7), np.log(0.9), TURN])
OLIVE = (0.7, 0.6, 0.1)


def _room() -> np.ndarray:
    return flat_panorama(ROOM, 2.6, PROBE, W, H)


def _feet(params: np.ndarray) -> np.ndarray:
    """The clicks on a box's four bottom corners, as a user clicks where it meets the floor."""
    x, y, lw, ld, _, turn = params
    corners = BoxFit(np.array([x, y, 0.0]), np.exp([lw, ld, 0.0]), float(turn), 0.0, 0).corners()[:4]
    return clicks_of(corners, PROBE, W, H)


def test_a_box_stays_a_box() -> None:
    panorama = with_box(_room(), CHAIR, 1.5, OLIVE)
    click = tuple(np.round(project(np.array([1.8, 0.6, 0.45 - 1.5]), W, H)))
    proxy = object_from_click(panorama, click, click_size=(W, H), probe=PROBE, inside=ROOM)
    assert proxy.kind == "box" and proxy.agreement >= 0.95
    assert proxy.size[2] == pytest.approx(0.9, rel=0.08)
    assert len(proxy.solid.vertices()) == 8


def test_a_seat_before_a_higher_back_gets_a_stepped_box() -> None:
    # A seat 0.45 m high, 0.5 m deep, and behind it (away from the probe) a back 0.95 m high, 0.2 m deep.
    along = np.array([-np.sin(TURN), np.cos(TURN)])
    seat_centre = np.array([1.8, 0.6]) - 0.1 * along
    back_centre = np.array([1.8, 0.6]) + 0.25 * along
    if np.dot(back_centre, along) < np.dot(seat_centre, along):
        along = -along  # the back behind the seat, seen from the probe
    seat = np.array([*(np.array([1.8, 0.6]) - 0.1 * along), np.log(0.8), np.log(0.5), np.log(0.45), TURN])
    back = np.array([*(np.array([1.8, 0.6]) + 0.25 * along), np.log(0.8), np.log(0.2), np.log(0.95), TURN])
    panorama = with_box(with_box(_room(), seat, 1.5, OLIVE), back, 1.5, OLIVE)
    click = tuple(np.round(project(np.append(seat[:2], 0.3 - 1.5), W, H)))
    proxy = object_from_click(panorama, click, click_size=(W, H), probe=PROBE, inside=ROOM)
    assert proxy.kind == "stepped box" and proxy.agreement >= 0.95
    # A seat seen from above trades its height against its depth: within 15 %.
    assert sorted(proxy.details["step_heights_m"]) == pytest.approx([0.45, 0.95], rel=0.15)
    assert proxy.size[2] == pytest.approx(0.95, rel=0.05)


def test_a_footprint_gives_a_prism_of_the_object_height() -> None:
    panorama = with_box(_room(), CHAIR, 1.5, OLIVE)
    feet = _feet(CHAIR)
    proxy = object_proxy(panorama, ObjectClicks("Chair", footprint=tuple(map(tuple, feet))), click_size=(W, H),
                         probe=PROBE, inside=ROOM)
    assert proxy.kind == "footprint prism" and proxy.agreement >= 0.95
    assert proxy.details["height_m"] == pytest.approx(0.9, rel=0.05)
    bottom = proxy.solid.vertices()[:4]
    assert np.allclose(bottom[:, 2], 0.0)
    assert bottom[:, :2].mean(axis=0) == pytest.approx(CHAIR[:2], abs=0.03)


@pytest.mark.parametrize(("change", "match"), [
    (lambda feet: feet[:2], "3 or more contact points, 2 clicked"),
    (lambda feet: feet[[0, 2, 1, 3]], "the footprint crosses itself"),
    (lambda feet: np.concatenate([feet[:1], [[feet[1][0], 200.0]], feet[2:]]), "contact point 1 .* not below"),
    (lambda feet: np.concatenate([feet[:3], [[W + 3.0, 300.0]]]), "contact point 3 .* outside the 1024 × 512"),
])
def test_a_bad_footprint_is_refused(change, match: str) -> None:
    with pytest.raises(DimredError, match=match) as error:
        object_from_footprint(_room(), tuple(map(tuple, change(_feet(CHAIR)))), click_size=(W, H), probe=PROBE)
    assert "\n" not in str(error.value)


def test_a_footprint_outside_the_room_is_refused() -> None:
    small = np.array([(-1.0, -1.0), (1.5, -1.0), (1.5, 1.0), (-1.0, 1.0)])
    with pytest.raises(DimredError, match=r"contact point .* outside the room's floor"):
        object_from_footprint(_room(), tuple(map(tuple, _feet(CHAIR))), click_size=(W, H), probe=PROBE, inside=small)
