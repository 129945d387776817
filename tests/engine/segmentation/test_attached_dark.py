"""A chair's dark legs beside its body are the object's; its shadow on the floor is not."""
from __future__ import annotations

import numpy as np

from addon.segmentation.seen import _attached_dark


def _room() -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    floor = np.array([0.30, 0.26, 0.22])
    image = floor * (1 + 0.05 * rng.standard_normal((80, 80, 1)))
    shown = np.zeros((80, 80), bool)
    shown[20:50, 25:55] = True  # the seat, as segmented
    image[shown] = [0.5, 0.5, 0.05]
    return image, shown


def test_dark_legs_joined_to_the_object_are_added() -> None:
    image, shown = _room()
    legs = np.zeros_like(shown)
    legs[50:58, 27:30] = legs[50:58, 50:53] = True
    image[legs] = [0.03, 0.015, 0.01]  # dark wood
    got = _attached_dark(image, shown, 10)
    assert got[legs].mean() > 0.9
    assert not (got & shown).any()


def test_a_shadow_in_the_floors_colour_and_dark_things_apart_are_left() -> None:
    image, shown = _room()
    shadow = np.zeros_like(shown)
    shadow[50:60, 30:50] = True
    image[shadow] *= 0.15  # the floor, in its own colour, barely lit
    apart = np.zeros_like(shown)
    apart[70:75, 5:10] = True  # a dark thing on the floor, not touching the object
    image[apart] = [0.03, 0.015, 0.01]
    got = _attached_dark(image, shown, 10)
    assert not got[shadow].any()
    assert not got[apart].any()
