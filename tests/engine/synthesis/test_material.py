"""The exemplar is the hole's own material: clutter beside it is never copied into it."""
from __future__ import annotations

import numpy as np

from addon.synthesis.material import border_material

_H, _W = 120, 160


def _wood(rng: np.random.Generator) -> np.ndarray:
    """Planks 8 cells wide of three shades with grain along them and dark seams."""
    cols = np.arange(_W)
    shade = np.array([1.0, 0.85, 1.12])[(cols // 8) % 3]
    grain = 1 + 0.08 * rng.standard_normal((_H, _W)).cumsum(axis=0) / np.sqrt(np.arange(1, _H + 1))[:, None]
    seam = np.where(cols % 8 == 0, 0.6, 1.0)
    base = np.array([0.45, 0.30, 0.18])
    return base * (shade * seam * grain * (1 + 0.03 * rng.standard_normal((_H, _W))))[..., None]


def _hole() -> np.ndarray:
    hole = np.zeros((_H, _W), bool)
    hole[50:74, 60:90] = True
    return hole


def test_a_rug_and_a_foot_beside_the_hole_are_left_out() -> None:
    rng = np.random.default_rng(1)
    image = _wood(rng)
    rug = np.zeros((_H, _W), bool)
    rug[40:110, 92:150] = True  # touches the hole's right side
    stripes = np.where((np.arange(_W) // 4) % 2, 0.85, 0.04)
    image[rug] = np.stack([stripes] * 3, axis=-1)[np.nonzero(rug)[1]]
    foot = np.zeros((_H, _W), bool)
    foot[76:80, 64:68] = True  # a dark leg just below the hole
    image[foot] = 0.02
    hole = _hole()
    known = ~hole
    got = border_material(image, known, hole, min_cells=64)
    assert got.source == "border material"
    assert not (got.exemplar & foot).any()
    assert (got.exemplar & rug).sum() < 0.02 * rug.sum()
    wood = known & ~rug & ~foot
    assert (got.exemplar & wood).sum() > 0.8 * wood.sum()
    # the foot and the rug's edge beside the hole are repainted, not left as context
    assert got.replaced[foot].all()
    assert not (got.replaced & got.exemplar).any()


def test_a_checker_keeps_both_colours() -> None:
    rows, cols = np.indices((_H, _W))
    tile = ((rows // 20 + cols // 20) % 2).astype(float)
    image = (0.08 + 0.7 * tile)[..., None] * np.array([1.0, 0.95, 0.9])
    image *= 1 + 0.02 * np.random.default_rng(2).standard_normal((_H, _W, 1))
    hole = _hole()
    got = border_material(image, ~hole, hole, min_cells=64)
    assert got.source == "border material"
    for colour in (tile == 0, tile == 1):
        assert (got.exemplar & colour).sum() > 0.9 * (~hole & colour).sum()
    assert not got.mostly_other


def test_a_surface_mostly_of_clutter_still_draws_on_the_border_material() -> None:
    rng = np.random.default_rng(3)
    image = _wood(rng)
    clutter = np.ones((_H, _W), bool)
    clutter[30:94, 40:110] = False  # only a margin of wood around the hole
    image[clutter] = np.array([0.1, 0.3, 0.6]) * (1 + 0.3 * rng.random((_H, _W, 1)))[clutter]
    hole = _hole()
    got = border_material(image, ~hole, hole, min_cells=64)
    assert got.source == "border material"
    assert got.mostly_other
    assert not (got.exemplar & clutter).any()


def test_seen_only_far_from_the_hole_the_whole_surface_is_used_without_a_warning() -> None:
    image = np.full((_H, _W, 3), 0.5)
    hole = _hole()
    known = ~hole & (np.indices((_H, _W))[1] > 150)  # seen only far away: no ring at all, nothing to tell
    got = border_material(image, known, hole, min_cells=64)
    assert got.source == "whole surface"
    assert np.array_equal(got.exemplar, known)
    assert not got.decided and not got.mostly_other


def test_without_any_match_the_whole_surface_is_used_and_said() -> None:
    hole = _hole()
    # around the hole a patchwork of colours each on one side only; the match is too small
    rows, cols = np.indices((_H, _W))
    sector = ((np.arctan2(rows - 62, cols - 75) + np.pi) / (2 * np.pi) * 8).astype(int) % 8
    image = np.array([[0.8, 0.1, 0.1], [0.1, 0.8, 0.1], [0.1, 0.1, 0.8], [0.8, 0.8, 0.1],
                      [0.1, 0.8, 0.8], [0.8, 0.1, 0.8], [0.05, 0.05, 0.05], [0.9, 0.9, 0.9]])[sector]
    got = border_material(image, ~hole, hole, min_cells=64)
    assert got.source == "whole surface" and got.decided
    assert np.array_equal(got.exemplar, ~hole)
    assert got.mostly_other


def test_the_same_input_gives_the_same_exemplar() -> None:
    image = _wood(np.random.default_rng(4))
    hole = _hole()
    a = border_material(image, ~hole, hole, min_cells=64)
    b = border_material(image, ~hole, hole, min_cells=64)
    assert np.array_equal(a.exemplar, b.exemplar) and a.share == b.share


def test_clutter_filling_the_ring_beyond_a_band_of_the_material_is_left_out() -> None:
    """A hole against the wall, on a band of wood between a rug and a desk chair's dark foot,
    which fill most directions a few cells farther out: the band right outside the hole decides."""
    rng = np.random.default_rng(5)
    image = _wood(rng)
    hole = _hole()
    known = ~hole & (np.indices((_H, _W))[1] >= 52)  # the wall left of the hole: no floor seen there
    rug = np.zeros((_H, _W), bool)
    rug[10:44, 52:] = True
    stripes = np.where((np.arange(_W) // 4) % 2, 0.85, 0.04)
    image[rug] = np.stack([stripes] * 3, axis=-1)[np.nonzero(rug)[1]]
    foot = np.zeros((_H, _W), bool)
    foot[44:120, 97:140] = True
    image[foot] = np.array([0.03, 0.02, 0.015]) * (1 + 0.3 * rng.random((_H, _W, 1)))[foot]
    got = border_material(image, known, hole, min_cells=64)
    assert got.source == "border material"
    wood = known & ~rug & ~foot
    assert (got.exemplar & wood).sum() > 0.8 * wood.sum()
    assert (got.exemplar & rug).sum() < 0.02 * rug.sum()
    assert not (got.exemplar & foot).any()


def test_a_dark_desk_in_the_floors_hue_is_left_out_where_the_shares_relax() -> None:
    """A hole against the wall on a floor whose printed light dims it toward a dark desk: the
    wood's own shades are found in too few directions, the shares relax to half of them and the
    desk's colour (the wood's hue, 8x darker) passes; it is far darker than the band right outside
    the hole and not found all around it (the hotel photograph's desk at 256x128)."""
    rng = np.random.default_rng(7)
    rows, cols = np.indices((_H, _W))
    image = _wood(rng) * np.exp(1.5 * (rows - 62) / 60.0)[..., None]
    hole = _hole()
    known = ~hole & (cols >= 52)
    desk = np.zeros((_H, _W), bool)
    desk[0:48, 52:150] = True
    image[desk] *= 0.12 * (1 + 0.3 * rng.random((_H, _W, 1)))[desk]
    got = border_material(image, known, hole, min_cells=64)
    assert got.source == "border material"
    assert not (got.exemplar & desk).any()
    wood = known & ~desk
    assert (got.exemplar & wood).sum() > 0.3 * wood.sum()


def test_a_tilings_dark_minority_is_kept() -> None:
    """Dark stripes a quarter of a tiling, ten times darker than its light ones, are found all
    around the hole: its material, however dark."""
    cols = np.indices((_H, _W))[1]
    dark = (cols % 20) < 5
    image = np.where(dark, 0.06, 0.75)[..., None] * np.array([1.0, 0.95, 0.9])
    image = image * (1 + 0.02 * np.random.default_rng(2).standard_normal((_H, _W, 1)))
    hole = _hole()
    got = border_material(image, ~hole, hole, min_cells=64)
    for colour in (dark, ~dark):
        assert (got.exemplar & colour).sum() > 0.95 * (~hole & colour).sum()
