"""The object's shadow the relighting left darker than its floor is lifted to the floor's level."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from addon.light.radiosity import LUMA
from addon.segmentation.masks import dilate
from addon.synthesis.material import border_material, wall_material
from addon.synthesis.shadow_lift import shadow_gain
from tests.engine.synthesis.test_material import _hole, _shade

_H, _W = 120, 160


def _floor(seed: int) -> np.ndarray:
    """A plain wood-coloured floor with a grain of 3 %."""
    grain = 1 + 0.03 * np.random.default_rng(seed).standard_normal((_H, _W, 1))
    return np.array([0.45, 0.30, 0.18]) * grain


def test_the_shadow_left_beside_the_hole_is_brought_to_the_floors_level_its_grain_kept() -> None:
    hole = _hole()
    shade = _shade(0.4)
    floor = _floor(3)
    image = floor * shade[..., None]
    material = border_material(image, ~hole, hole, min_cells=64)
    assert material.shadow is not None and material.shadow.any()
    gain = shadow_gain(image, ~hole, material, hole)
    lifted = (image * gain[..., None]) @ LUMA
    level = np.median((floor @ LUMA)[~hole])
    # (the test's shadow ends sideways in a hard edge, which a 5x5 level blurs: its inside)
    deep = (shade < 0.5) & ~hole & dilate(hole, 6) & (np.abs(np.arange(_W) - 75) <= 14)[None, :]
    assert abs(np.median(lifted[deep]) / level - 1) < 0.08
    # the shadow's grain is kept: the lift is smooth over a few cells
    before = (image @ LUMA)[deep]
    assert 0.5 < np.std(lifted[deep] / np.median(lifted[deep])) / np.std(before / np.median(before)) < 1.5
    # far from it nothing changes, and nothing is darkened
    assert np.all(gain[~dilate(material.shadow, 8)] == 1.0)
    assert gain.min() >= 1.0 and gain.max() <= 4.0


def test_a_floor_without_the_objects_shadow_is_not_lifted() -> None:
    hole = _hole()
    image = _floor(4)
    assert shadow_gain(image, ~hole, border_material(image, ~hole, hole, min_cells=64), hole) is None
    # nor is a wall, whose material has no shadow
    assert shadow_gain(image, ~hole, wall_material(~hole), hole) is None


def test_a_few_dark_cells_beside_the_hole_are_the_floors_own_not_lifted() -> None:
    hole = _hole()
    shade = _shade(0.4)
    image = _floor(6) * shade[..., None]
    material = border_material(image, ~hole, hole, min_cells=64)
    assert shadow_gain(image, ~hole, material, hole) is not None
    few = np.zeros_like(hole)
    few[74:76, 74:77] = material.shadow[74:76, 74:77]  # six cells along a border of about a hundred
    assert few.any()
    assert shadow_gain(image, ~hole, replace(material, shadow=few), hole) is None
