"""Bad clicks are refused with one line that names the click, before anything is built."""
from __future__ import annotations

import json

import numpy as np
import pytest

from addon.errors import DimredError
from addon.roommatch import clicks as click_file
from addon.roommatch.clicks import KnownLength, ObjectClicks, RoomClicks
from addon.roommatch.fit import fit_room
from tests.engine.roommatch.room_truth import clicks_of, floor_points

W, H = 1024, 512
BOX = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
PROBE = np.array([0.0, 0.0, 1.5])
FLOOR = [tuple(p) for p in clicks_of(floor_points(BOX), PROBE, W, H)]


def _refused(make, match: str) -> None:
    with pytest.raises(DimredError, match=match) as error:
        make()
    assert "\n" not in str(error.value)


def test_fewer_than_three_corners() -> None:
    _refused(lambda: RoomClicks(W, H, tuple(FLOOR[:2])), "3 or more corners, 2 clicked")


def test_a_corner_above_the_horizon() -> None:
    high = [FLOOR[0], (FLOOR[1][0], 200.0), *FLOOR[2:]]
    _refused(lambda: fit_room(RoomClicks(W, H, tuple(high))), "floor corner 1 .* not below the horizon")


def test_a_corner_on_the_horizon() -> None:
    level = [FLOOR[0], (FLOOR[1][0], H / 2 - 0.5), *FLOOR[2:]]
    _refused(lambda: fit_room(RoomClicks(W, H, tuple(level))), "floor corner 1 .* not below the horizon")


def test_a_self_crossing_polygon() -> None:
    crossed = [FLOOR[0], FLOOR[2], FLOOR[1], FLOOR[3]]
    _refused(lambda: fit_room(RoomClicks(W, H, tuple(crossed))), "crosses itself")


@pytest.mark.parametrize("point", [(W - 0.5, 300.0), (-1.0, 300.0), (100.0, H), (100.0, -0.6)])
def test_a_click_outside_the_panorama(point: tuple[float, float]) -> None:
    _refused(lambda: RoomClicks(W, H, (*FLOOR[:3], point)), "floor corner 3 .* outside the 1024 × 512 panorama")


@pytest.mark.parametrize("height", [0.0, -1.6])
def test_a_height_at_or_below_zero(height: float) -> None:
    _refused(lambda: RoomClicks(W, H, tuple(FLOOR), camera_height=height), "camera height must be above 0")


def test_a_known_length_at_or_below_zero() -> None:
    _refused(lambda: RoomClicks(W, H, tuple(FLOOR), known_length=KnownLength("wall", 0.0)),
             "known length must be above 0")


def test_the_probe_outside_the_polygon() -> None:
    # Three corners of the room's one half: the probe at the room's middle is outside them.
    half = [tuple(p) for p in clicks_of(floor_points(np.array([(0.5, -1.5), (3.0, -1.5), (3.0, 2.5)])), PROBE, W, H)]
    _refused(lambda: fit_room(RoomClicks(W, H, tuple(half))), "probe centre lies outside")


def test_manhattan_refuses_a_corner_between_parallel_walls() -> None:
    extra = clicks_of(floor_points(np.array([(0.5, -1.5)])), PROBE, W, H)[0]
    five = [FLOOR[0], tuple(extra), *FLOOR[1:]]
    _refused(lambda: fit_room(RoomClicks(W, H, tuple(five), manhattan=True)), "walls 0 and 1 run the same way")


def test_a_ceiling_click_below_the_horizon() -> None:
    _refused(lambda: fit_room(RoomClicks(W, H, tuple(FLOOR), ceiling=(100.0, 400.0))),
             "ceiling point .* not above the horizon")


_OBJECTS = '{{"width": 8, "height": 4, "floor": [[1, 3], [2, 3], [3, 3]], "objects": [{}]}}'


@pytest.mark.parametrize(("text", "match"), [
    ("[1, 2]", "must hold a JSON object"),
    ('{"width": 8, "height": 4}', "no 'floor'"),
    ('{"width": 8, "height": 4, "floor": [[1, 2]], "colour": 1}', "unknown keys"),
    ('{"width": 8, "height": 4, "floor": [[1, 2], [2, 3], [3]]}', r"floor corner 2 must be \[x, y\]"),
    (('{"width": 8, "height": 4, "floor": [[1, 3], [2, 3], [3, 3]], "camera_height": 1.6,'
     ' "known_length": {"kind": "wall", "edge": 0, "metres": 3}}'), "not both"),
    ("{", "not valid JSON"),
    (_OBJECTS.format('{"name": "A", "click": [1, 3], "footprint": [[1, 3], [2, 3], [3, 3]]}'), "one of them"),
    (_OBJECTS.format('{"name": "A", "footprint": [[1, 3], [2, 3]]}'), "footprint of 'A' needs 3 or more"),
    (_OBJECTS.format('{"name": "A", "click": [9, 3]}'), r"click in 'A' \(9, 3\) lies outside the 8 × 4"),
    (_OBJECTS.format('{"click": [1, 3]}'), "object 0 must be an object with a 'name'"),
])
def test_a_bad_click_file(text: str, match: str) -> None:
    _refused(lambda: click_file.from_json(text), match)


def test_the_click_file_round_trips() -> None:
    clicks = RoomClicks(W, H, tuple(FLOOR), ceiling=(10.0, 100.0),
                        known_length=KnownLength("vertical", 2.0, start=(1.0, 300.0), end=(1.0, 200.0)),
                        manhattan=True, objects=(ObjectClicks("Chair", click=(500.0, 350.0)),
                                                 ObjectClicks("Table", footprint=((1.0, 300.0), (9.0, 300.0),
                                                                                  (5.0, 320.0)))))
    assert click_file.from_json(json.dumps(clicks.to_dict())) == clicks
    assert clicks.click_count() == 4 + 1 + 2 + 1 + 3  # corners, ceiling, the length's ends, the objects
