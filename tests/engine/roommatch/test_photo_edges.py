"""The edge measure: the true room's edges lie on a flat panorama's, a misplaced room's do not."""
from __future__ import annotations

import dataclasses

import numpy as np

from addon.roommatch.clicks import RoomClicks
from addon.roommatch.fit import fit_room
from addon.roommatch.photo_edges import edge_offsets
from addon.roommatch.refine import refine_clicks
from tests.engine.roommatch.room_truth import clicks_of, flat_panorama, floor_points

BOX = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
PROBE = np.array([0.0, 0.0, 1.5])


def _room(width: int = 1024):
    floor = clicks_of(floor_points(BOX), PROBE, width, width // 2, rounded=False)
    return fit_room(RoomClicks(width, width // 2, tuple(map(tuple, floor)), camera_height=1.5), ceiling_height=2.6)


def test_the_true_room_lies_on_the_panorama_edges() -> None:
    panorama = flat_panorama(BOX, 2.6, PROBE, 2048, 1024)
    found = edge_offsets(panorama, _room())
    assert np.all(found.shown > 0.8)
    assert np.nanmax(found.offsets) < 0.5


def test_a_lower_ceiling_is_seen_off_its_edges() -> None:
    panorama = flat_panorama(BOX, 2.6, PROBE, 2048, 1024)
    room = dataclasses.replace(_room(), ceiling_height=2.45)
    found = edge_offsets(panorama, room)
    ceiling = found.offsets[4:8]
    assert not np.any(ceiling <= 2.0)  # off by more than 2 px, or no edge within the search at all
    assert np.all(found.offsets[:4] < 0.5)


def test_refined_clicks_land_on_the_photograph_corners() -> None:
    # Clicks a whole pixel off at 512 wide; the panorama twice as wide shows the edges.
    width = 512
    floor = clicks_of(floor_points(BOX), PROBE, width, width // 2) + np.array([[1, -1], [-1, 1], [1, 1], [-1, -1]])
    clicks = RoomClicks(width, width // 2, tuple(map(tuple, floor)), camera_height=1.5)
    room = fit_room(clicks, ceiling_height=2.6)
    refined, shown = refine_clicks(flat_panorama(BOX, 2.6, PROBE, 2048, 1024), clicks, room)
    assert shown.all()
    before = np.abs(room.corners - BOX).max()
    after = np.abs(fit_room(refined, ceiling_height=2.6).corners - BOX).max()
    assert before > 0.05 and after < 0.01
