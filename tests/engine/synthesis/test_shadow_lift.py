"""The object's shadow the relighting left darker than its floor is lifted to the floor's level."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from addon.light.radiosity import LUMA
from addon.segmentation.masks import dilate
from addon.synthesis.material import Material, border_material, wall_material
from addon.synthesis.shadow_lift import shadow_lift
from tests.engine.synthesis.test_material import _hole, _shade

_H, _W = 120, 160


def _gain(image: np.ndarray, known: np.ndarray, material: Material, hole: np.ndarray, *,
          relit: np.ndarray | None = None) -> np.ndarray | None:
    """The raster's gain (h, w, 3) that lifts the material's shadow, None where there is none."""
    lift = shadow_lift(image, known, material, hole, relit=relit)
    return None if lift is None else lift.raster_gain(image, known)


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
    gain = _gain(image, ~hole, material, hole)
    lifted = (image * gain) @ LUMA
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
    assert _gain(image, ~hole, border_material(image, ~hole, hole, min_cells=64), hole) is None
    # nor is a wall, whose material has no shadow
    assert _gain(image, ~hole, wall_material(~hole), hole) is None


def test_a_few_dark_cells_beside_the_hole_are_the_floors_own_not_lifted() -> None:
    hole = _hole()
    shade = _shade(0.4)
    image = _floor(6) * shade[..., None]
    material = border_material(image, ~hole, hole, min_cells=64)
    assert _gain(image, ~hole, material, hole) is not None
    few = np.zeros_like(hole)
    few[74:76, 74:77] = material.shadow[74:76, 74:77]  # six cells along a border of about a hundred
    assert few.any()
    assert _gain(image, ~hole, replace(material, shadow=few), hole) is None


def _bounced(shade: np.ndarray, floor: np.ndarray) -> np.ndarray:
    """`floor` (h, w, 3) darkened by `shade` (h, w), the light left in the shade the floor's own,
    bounced: its colour goes from the floor's halfway to the floor's colour squared as it darkens
    to half."""
    tint = np.array([0.45, 0.30, 0.18]) / 0.45
    depth = (1 - shade)[..., None] / 0.5
    return floor * shade[..., None] * tint ** (0.5 * np.clip(depth, 0.0, 1.0))


def test_a_shadow_in_the_floors_bounced_colour_is_lifted_to_the_floors_colour() -> None:
    """The light left in a shadow is the floor's own, bounced: the shadow is more saturated
    than the floor. It is taken for shadow and lifted per channel, so it takes the floor's
    colour, not only its level (one factor left a warm floor's shadow an orange strip)."""
    hole = _hole()
    shade = _shade(0.5)
    floor = _floor(7)
    image = _bounced(shade, floor)
    material = border_material(image, ~hole, hole, min_cells=64)
    assert material.shadow is not None and material.shadow.sum() > 200
    gain = _gain(image, ~hole, material, hole)
    assert gain is not None
    deep = (shade < 0.6) & ~hole & dilate(hole, 6) & (np.abs(np.arange(_W) - 75) <= 14)[None, :]
    chroma = lambda x: x / x.sum(axis=-1, keepdims=True)  # noqa: E731
    want = np.median(chroma(floor[~hole]), axis=0)
    before = np.median(chroma(image[deep]), axis=0)
    after = np.median(chroma((image * gain)[deep]), axis=0)
    assert np.abs(before - want).max() > 0.04
    assert np.abs(after - want).max() < 0.01


def test_a_darkening_the_relighting_does_not_brighten_is_not_lifted() -> None:
    """A floor darkened beside the hole by something else (a wall's shade, in the floor's
    bounced colour like a shadow) is no shadow of the object: where the relighting does not
    brighten it (E' / E about 1), nothing is lifted."""
    hole = _hole()
    image = _bounced(_shade(0.5), _floor(8))
    unchanged = np.ones((_H, _W))
    material = border_material(image, ~hole, hole, min_cells=64, relit=unchanged)
    assert material.shadow is None or not material.shadow.any()
    assert _gain(image, ~hole, material, hole) is None
    # relit only within 4 rows of the hole: the shadow stops there, and its penumbra with it
    relit = np.where(np.indices((_H, _W))[0] < 78, 1.5, 1.0)
    material = border_material(image, ~hole, hole, min_cells=64, relit=relit)
    gain = _gain(image, ~hole, material, hole)
    assert gain is not None and (gain[74:78] > 1).any()
    # (a cell past it carries its weight, for the pixels looked up between: `test_a_shadows_sharp_edge...`)
    assert np.all(gain[79:] == 1.0)


def test_the_shadow_is_lifted_to_the_floor_beside_it_not_to_the_floors_median() -> None:
    """A glossy floor seen farther away is paler: the shadow below the hole is lifted to the
    floor below it, not to the median of the floor all around."""
    hole = _hole()
    shade = _shade(0.4)
    rows = np.indices((_H, _W))[0]
    floor = _floor(9) * np.where(rows < 62, 1.4, 1.0)[..., None]  # the far side, above, paler
    image = floor * shade[..., None]
    material = border_material(image, ~hole, hole, min_cells=64)
    gain = _gain(image, ~hole, material, hole)
    assert gain is not None
    deep = (shade < 0.5) & ~hole & dilate(hole, 6) & (np.abs(np.arange(_W) - 75) <= 14)[None, :]
    near = np.median((floor @ LUMA)[(rows > 90) & ~hole])
    assert abs(np.median(((image * gain) @ LUMA)[deep]) / near - 1) < 0.08


def test_a_shadow_far_deeper_than_the_relighting_made_it_is_lifted_no_more_than_its_square() -> None:
    """A box for an armchair shades less than the armchair, but not far less: a cell the proxy
    hardly shades (E' / E of 1.1) that is half the floor's level is something else's shadow or
    paint, lifted at most by the relighting's change squared. Where the proxy shades it deeply,
    it is lifted to the floor."""
    hole = _hole()
    shade = _shade(0.5)
    image = _floor(10) * shade[..., None]
    deep = (shade < 0.6) & ~hole & dilate(hole, 6) & (np.abs(np.arange(_W) - 75) <= 14)[None, :]
    lifts = {}
    for change in (1.1, 2.5):
        relit = np.full((_H, _W), change)
        material = border_material(image, ~hole, hole, min_cells=64, relit=relit)
        gain = _gain(image, ~hole, material, hole, relit=relit)
        assert gain is not None
        lifts[change] = np.median((gain @ LUMA)[deep])
    assert lifts[1.1] <= 1.1**2 + 1e-6
    assert lifts[2.5] > 1.6


def test_a_shadows_sharp_edge_is_lifted_to_its_last_cell_and_the_floor_beside_it_not_at_all() -> None:
    """Each cell (or pixel) is lifted by its own deficit against the mean of the cells around it
    alike in luminance: the shadow's last row is not averaged with the lit floor beside it
    (under-lifted, it stayed a dark line along the real hotel armchair's fill), nor the floor's
    first row with the shadow (over-lifted). Its weight reaches a cell past the shadow, so
    pixels looked up between them are lifted too."""
    hole = _hole()
    rows = np.indices((_H, _W))[0]
    shade = np.where((rows >= 74) & (rows < 80) & (np.abs(np.arange(_W) - 75) <= 18)[None, :], 0.4, 1.0)
    floor = _floor(11)
    image = floor * shade[..., None]
    material = border_material(image, ~hole, hole, min_cells=64)
    lift = shadow_lift(image, ~hole, material, hole)
    assert lift is not None
    gain = lift.raster_gain(image, ~hole) @ LUMA
    middle = np.abs(np.arange(_W) - 75) <= 10
    level = np.median((floor @ LUMA)[~hole])
    last = ((image @ LUMA) * gain)[79, middle]
    assert abs(np.median(last) / level - 1) < 0.1
    assert np.all(lift.weight[79, middle] == 1.0)  # (its 3x3 deviation is too rough for the shadow's own cells)
    assert np.all(gain[80, middle] < 1.05)


def test_a_proxys_shadow_a_cell_or_two_short_of_the_objects_bounds_the_lift_as_if_it_reached() -> None:
    """A proxy modelled a few centimetres off casts its shadow as far off: where the relighting's
    change falls to 1 two rows before the photographed shadow ends, the bound on those rows'
    lift is the one on the rows it covers."""
    hole = _hole()
    shade = np.where((np.indices((_H, _W))[0] >= 74) & (np.abs(np.arange(_W) - 75) <= 18)[None, :]
                     & (np.indices((_H, _W))[0] < 82), 0.5, 1.0)
    image = _floor(12) * shade[..., None]
    relit = np.where(np.indices((_H, _W))[0] < 80, 2.0, 1.0)
    material = border_material(image, ~hole, hole, min_cells=64, relit=relit)
    lift = shadow_lift(image, ~hole, material, hole, relit=relit)
    assert lift is not None and lift.bound is not None
    middle = np.abs(np.arange(_W) - 75) <= 10
    assert np.all(lift.bound[80:82, middle] >= (2.0 / 1.05) ** 2 - 1e-9)
    assert np.all(lift.bound[83:, middle] == 1.0)
