"""A band crossing the hole between two materials, or lining up across it on one, is continued
across it, each side with its own material."""
from __future__ import annotations

import numpy as np
import pytest

from addon.synthesis.crossing import fill_crossing, find_crossing
from addon.synthesis.texture import SynthesisParams

_H, _W = 128, 160
_GREEN, _BROWN, _YELLOW = np.array([0.10, 0.16, 0.06]), np.array([0.16, 0.11, 0.07]), np.array([0.55, 0.42, 0.05])


def _lane(*, far: np.ndarray = _BROWN, width: float = 7.0, slope: float = 0.35) -> tuple[np.ndarray, np.ndarray]:
    """A floor of `_GREEN` above a straight lane of `_YELLOW` and `far` below it, grainy and lit
    brighter to the right, and the lane's signed distance across (positive below)."""
    rng = np.random.default_rng(4)
    rows, cols = np.indices((_H, _W)).astype(float)
    across = (rows - (60 + slope * (cols - 80))) / np.hypot(1.0, slope)
    colour = np.where((across < -width / 2)[..., None], _GREEN, np.where((across > width / 2)[..., None], far, _YELLOW))
    light = 1 + 0.3 * cols / _W
    grain = 1 + 0.12 * rng.standard_normal((_H, _W))
    return colour * (light * grain)[..., None], across


def _hole() -> np.ndarray:
    hole = np.zeros((_H, _W), bool)
    hole[44:78, 62:100] = True
    return hole


def _region_means(image: np.ndarray, mask: np.ndarray) -> np.ndarray:
    return image[mask].mean(axis=0)


def test_a_lane_between_two_floors_runs_on_across_the_hole() -> None:
    truth, across = _lane()
    hole = _hole()
    known = ~hole
    image = np.where(hole[..., None], 0.0, truth)
    crossing = find_crossing(image, known, hole)
    assert crossing is not None
    band = crossing.regions == crossing.band
    lane = hole & (np.abs(across) < 2.0)  # the lane's middle, away from its edges
    assert band[lane].all()
    assert not band[hole & (np.abs(across) > 6.0)].any()
    filled = fill_crossing(crossing, image, known, SynthesisParams(), seed=0)
    for part in (lane, hole & (across < -6), hole & (across > 6)):  # each side its own colour and level
        np.testing.assert_allclose(_region_means(filled.image, part), _region_means(truth, part), rtol=0.1)
    np.testing.assert_array_equal(filled.image[known], image[known].astype(np.float32))
    # the sides' copies come from their own colour's cells
    src = filled.sources[hole & (across > 6)]
    src = src[src[:, 0] >= 0]
    assert len(src) and (across[src[:, 0], src[:, 1]] > 3.5).all()


def test_a_lane_in_line_across_one_floor_runs_on_across_the_hole() -> None:
    truth, across = _lane(far=_GREEN)
    hole = _hole()
    crossing = find_crossing(np.where(hole[..., None], 0.0, truth), ~hole, hole)
    assert crossing is not None
    band = crossing.regions == crossing.band
    assert band[hole & (np.abs(across) < 2.0)].all()
    sides = crossing.regions[hole & (np.abs(across) > 6.0)]
    assert (sides != crossing.band).all() and len(np.unique(sides)) == 1  # one floor on both sides



def test_a_side_lit_on_one_half_meets_both_its_colours() -> None:
    """Below the lane, light printed on the floor's right half reads as a colour of its own, the
    commonest beside the lower piece but for the dark left half's. The piece meets both: taken
    from the lit colour alone, its level at the hole's left side is twice the dark floor's."""
    truth, across = _lane(slope=0.0)
    rows, cols = np.indices((_H, _W))
    lit = (across > 4) & (cols >= 78)
    truth[lit] *= 3.0
    hole = _hole()
    image = np.where(hole[..., None], 0.0, truth)
    crossing = find_crossing(image, ~hole, hole)
    assert crossing is not None
    lower = crossing.regions[hole & (across > 6)]
    lit_colour = np.bincount(crossing.labels[lit & ~hole & (rows < 84)] + 1).argmax() - 1
    assert len(np.unique(lower)) == 1 and lit_colour == lower[0]
    filled = fill_crossing(crossing, image, ~hole, SynthesisParams(), seed=0)
    for part in (hole & (across > 6) & (cols < 66), hole & (across > 6) & (cols > 94)):
        np.testing.assert_allclose(_region_means(filled.image, part), _region_means(truth, part), rtol=0.25)


@pytest.mark.parametrize("far", ["green", "brown"])
def test_a_band_runs_on_under_a_stool_whose_legs_reach_through_it(far: str) -> None:
    """A round seat above the lane, its legs reaching down through the lane into the floor beyond:
    the lane meets the hole's border in wide runs on either side of the legs, with a narrow side
    between them."""
    truth, across = _lane(far=_GREEN if far == "green" else _BROWN, width=10.0, slope=0.1)
    rows, cols = np.indices((_H, _W))
    hole = (np.hypot(rows - 44, cols - 80) <= 14) | ((rows >= 44) & (rows < 84) & (np.abs(cols - 80) <= 3))
    crossing = find_crossing(np.where(hole[..., None], 0.0, truth), ~hole, hole)
    assert crossing is not None
    band = crossing.regions == crossing.band
    assert band[hole & (np.abs(across) < 3.0)].all()
    assert not band[hole & (np.abs(across) > 8.0)].any()


def test_a_striped_band_of_the_floor_s_mean_colour_is_told_by_its_texture() -> None:
    """A rug's black and white stripes, averaging to the floor's colour over a few cells, crossing
    the hole between two floors that read as one colour."""
    truth, across = _lane(far=_GREEN * 1.15, width=12.0)
    rows, cols = np.indices((_H, _W))
    stripes = np.where(((rows + cols) // 2 % 2 == 0)[..., None], 1.85, 0.15)
    rug = np.abs(across) <= 6.0
    truth[rug] = (_GREEN * stripes)[rug] * (1 + 0.3 * cols / _W)[rug, None]
    hole = _hole()
    crossing = find_crossing(np.where(hole[..., None], 0.0, truth), ~hole, hole)
    assert crossing is not None
    assert (crossing.regions == crossing.band)[hole & (np.abs(across) < 3.0)].all()


def test_a_stripe_out_of_line_across_one_floor_is_no_band() -> None:
    """A stripe reaching the hole from above and one from below, a few cells apart across: two
    things that end under the object, not one that passes."""
    image, _ = _lane(far=_GREEN, width=0.0)
    hole = _hole()
    image[4:44, 68:75] = _YELLOW
    image[78:124, 86:93] = _YELLOW
    assert find_crossing(image, ~hole, hole) is None



@pytest.mark.parametrize("seed", [0, 1, 3])
def test_two_smooth_stripes_of_other_colours_in_line_are_no_band(seed: int) -> None:
    """A grey stripe reaching the hole from the left and a yellow one from the right, in line,
    both smooth on a grainy floor: the texture reads them as one colour (as it does for these
    grains without the chromaticity test), but they are two things that meet under the object (a
    sunlit patch, a printed armchair), not one band."""
    rng = np.random.default_rng(seed)
    _, across = _lane(width=8.0)
    cols = np.indices((_H, _W))[1]
    image = np.where((across < 0)[..., None], _GREEN, _BROWN) * (1 + 0.08 * rng.standard_normal((_H, _W)))[..., None]
    stripe = np.abs(across) <= 4
    image[stripe] = np.where((cols < 80)[..., None], np.array([0.4, 0.42, 0.45]), _YELLOW)[stripe]
    hole = _hole()
    assert find_crossing(np.where(hole[..., None], 0.0, image), ~hole, hole) is None


@pytest.mark.parametrize("case", ["checker", "plain"])
def test_nothing_crosses_where_nothing_tells_it_does(case: str) -> None:
    hole = _hole()
    if case == "checker":
        rows, cols = np.indices((_H, _W))
        image = np.where((((rows // 12) + (cols // 12)) % 2 == 0)[..., None], _GREEN, _YELLOW)
    else:
        image, _ = _lane(far=_GREEN, width=0.0)
    assert find_crossing(image, ~hole, hole) is None


def test_dark_legs_in_line_on_two_sides_of_one_floor_are_no_band() -> None:
    image, _ = _lane(far=_GREEN, width=0.0)
    hole = _hole()
    legs = np.zeros((_H, _W), bool)
    legs[20:44, 78:82] = True  # a dark leg above the hole and one below, in line
    legs[78:104, 78:82] = True
    image[legs] = 0.01
    assert find_crossing(image, ~hole, hole) is None


def test_a_band_seen_on_one_side_only_is_no_crossing() -> None:
    truth, across = _lane()
    hole = _hole()
    known = ~hole & ~((np.indices((_H, _W))[1] > 100) & (np.abs(across) < 12))  # its far end unseen
    assert find_crossing(np.where(known[..., None], truth, 0.0), known, hole) is None


def test_a_band_lined_up_across_a_border_partly_unseen_runs_on() -> None:
    truth, across = _lane()
    hole = _hole()
    rows, cols = np.indices((_H, _W))
    known = ~hole & ~((rows < 44) & (cols >= 56) & (cols <= 106))  # the floor above the hole unseen
    crossing = find_crossing(np.where(known[..., None], truth, 0.0), known, hole)
    assert crossing is not None
    band = crossing.regions == crossing.band
    assert band[hole & (np.abs(across) < 2.0)].all()
    assert not band[hole & (np.abs(across) > 6.0)].any()


def test_the_floor_between_two_colours_and_a_gap_is_no_band() -> None:
    """The floor meets the hole above and below it, a yellow patch on its left, a brown one and
    the raster's edge on its right: the floor is the hole's material, not a band between them."""
    image, _ = _lane(far=_GREEN, width=0.0)
    hole = _hole()
    rows, cols = np.indices((_H, _W))
    image[(cols < 62) & (rows >= 50) & (rows < 72)] = _YELLOW
    image[(cols > 100) & (rows >= 50) & (rows < 60)] = _BROWN
    known = ~hole & ((cols < 101) | ((rows >= 50) & (rows < 60)))
    assert find_crossing(np.where(known[..., None], image, 0.0), known, hole) is None
