"""The suggestion from the photograph: traced on flat panoramas of rooms with right-angled
walls it proposes their corners; on a panorama without walls it says it found none."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from addon.roommatch.fit import fit_room
from addon.roommatch.suggest import suggest_room
from tests.engine.roommatch.room_truth import distance_errors, flat_panorama

BOX = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
L_ROOM = np.array([(-2.0, -1.6), (3.4, -1.6), (3.4, 0.9), (1.2, 0.9), (1.2, 2.8), (-2.0, 2.8)])


@pytest.mark.parametrize(("corners", "probe"), [(BOX, (0.0, 0.0, 1.5)), (L_ROOM, (0.3, -0.2, 1.55))])
def test_the_suggestion_finds_the_corners(corners: np.ndarray, probe: tuple[float, float, float]) -> None:
    probe = np.asarray(probe)
    found = suggest_room(flat_panorama(corners, 2.6, probe, 1024, 512), width=2048, height=1024)
    assert found.clicks is not None and found.clicks.manhattan, found.message
    assert found.message.startswith(f"suggested {len(corners)} floor corners")
    room = fit_room(dataclasses.replace(found.clicks, camera_height=probe[2]), origin=tuple(probe[:2]))
    nearest = np.array([room.corners[np.argmin(np.linalg.norm(room.corners - c, axis=1))] for c in corners])
    assert distance_errors(nearest, corners, probe).max() < 0.01


def test_no_walls_no_suggestion() -> None:
    noise = np.random.default_rng(3).random((256, 512, 3)).astype(np.float32) + 0.1
    found = suggest_room(noise, width=512, height=256)
    assert found.clicks is None
    assert found.message.startswith("no room suggested: ") and found.message.endswith("click the floor's corners")
