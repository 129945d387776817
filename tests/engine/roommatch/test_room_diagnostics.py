"""The room diagnostics picture draws every edge where it reprojects."""
from __future__ import annotations

import numpy as np

from addon.roommatch.clicks import RoomClicks
from addon.roommatch.diagnostics import room_picture
from addon.roommatch.fit import fit_room
from tests.engine.roommatch.room_truth import clicks_of, flat_panorama, floor_points

BOX = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
PROBE = np.array([0.0, 0.0, 1.5])


def test_the_picture_draws_the_floor_edges_at_their_reprojection() -> None:
    floor = clicks_of(floor_points(BOX), PROBE, 512, 256)
    clicks = RoomClicks(512, 256, tuple(map(tuple, floor)), camera_height=1.5)
    room = fit_room(clicks, ceiling_height=2.6)
    picture = room_picture(flat_panorama(BOX, 2.6, PROBE, 512, 256), room, clicks)
    assert picture.shape == (256, 512, 3) and picture.dtype == np.uint8
    green = (picture[..., 1] > 200) & (picture[..., 0] < 120) & (picture[..., 2] < 150)
    # The floor edge below the image centre (+X wall, 3 m away) at its row, 1.5 m below the camera.
    row = round(256 * (0.5 + np.arctan2(1.5, 3.0) / np.pi) - 0.5)
    assert green[row - 1:row + 2, 255:257].any()
    assert green.sum() > 512  # the floor's outline runs round the whole panorama
    assert not green[:128].any()  # and only below the horizon
