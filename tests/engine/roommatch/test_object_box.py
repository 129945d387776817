"""Object from Photo from arrays: one click inside a box standing on the floor of a flat panorama
gives back its place, size and turn, its silhouette agreeing with the outline."""
from __future__ import annotations

import numpy as np
import pytest

from addon.errors import DimredError
from addon.roommatch.object_box import BoxFit, box_from_click, refit_box
from addon.roommatch.projection import project
from tests.engine.roommatch.room_truth import flat_panorama, with_box

BOX = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
PROBE = np.array([0.0, 0.0, 1.5])
# An armchair-sized box 2 m in front of the probe, a little to the side, turned 20 degrees.
CHAIR = np.array([1.8, 0.6, np.log(0.8), np.log(0.7), np.log(0.9), np.radians(20.0)])


def test_one_click_gives_the_box() -> None:
    panorama = with_box(flat_panorama(BOX, 2.6, PROBE, 1024, 512), CHAIR, 1.5, (0.7, 0.6, 0.1))
    click = project(np.array([1.8, 0.6, 0.45 - 1.5]), 1024, 512)  # the box's middle
    box = box_from_click(panorama, tuple(np.round(click)), click_size=(1024, 512), probe=PROBE)
    assert box.agreement >= 0.95
    assert box.bottom[:2] == pytest.approx(CHAIR[:2], abs=0.05)
    assert box.bottom[2] == 0.0
    # A box turned by a quarter turn more, its width and depth swapped, is the same box.
    quarters = round((np.degrees(box.turn) - 20.0) / 90.0)
    size = box.size[[1, 0, 2]] if quarters % 2 else box.size
    assert size == pytest.approx(np.exp(CHAIR[2:5]), rel=0.08)
    assert abs(np.degrees(box.turn) - 20.0 - 90.0 * quarters) < 4.0


def test_a_click_on_bare_wall_is_refused() -> None:
    panorama = flat_panorama(BOX, 2.6, PROBE, 1024, 512)
    with pytest.raises(DimredError):
        box_from_click(panorama, (512.0, 200.0), click_size=(1024, 512), probe=PROBE)


def test_a_box_proxy_refits_each_size() -> None:
    # The proxy a user modelled by eye: 10 cm off, 8 degrees turned, 0.8 m high for a 0.95 m object.
    truth = np.array([1.8, 0.6, np.log(0.8), np.log(0.7), np.log(0.95), np.radians(20.0)])
    panorama = with_box(flat_panorama(BOX, 2.6, PROBE, 1024, 512), truth, 1.5, (0.7, 0.6, 0.1))
    guess = BoxFit(bottom=np.array([1.9, 0.55, 0.0]), size=np.array([0.7, 0.7, 0.8]), turn=np.radians(28.0),
                   agreement=0.0, outline_pixels=0)
    box = refit_box(panorama, guess.corners(), probe=PROBE)
    assert box.agreement >= 0.95
    assert box.size[2] == pytest.approx(0.95, rel=0.05)
    assert box.bottom[:2] == pytest.approx(truth[:2], abs=0.05)


def test_refit_refuses_what_is_no_box() -> None:
    corners = BoxFit(bottom=np.array([1.9, 0.55, 0.0]), size=np.array([0.7, 0.7, 0.8]), turn=0.3,
                     agreement=0.0, outline_pixels=0).corners()
    corners[5] += (0.1, 0.0, 0.0)  # a top corner pulled aside
    with pytest.raises(DimredError, match="not an upright box"):
        refit_box(flat_panorama(BOX, 2.6, PROBE, 512, 256), corners, probe=PROBE)
