"""The exemplar is the hole's own material: clutter beside it is never copied into it."""
from __future__ import annotations

import numpy as np

from addon.segmentation.masks import dilate
from addon.synthesis.material import (
    _shadow_colours,
    _shadow_halo,
    border_material,
    colour_features,
    log_luminance,
    sharp_exemplar,
)

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


def _shade(depth: float) -> np.ndarray:
    """(h, w) the object's soft shadow below the hole: `depth` of the light at the hole, fading
    out over 12 cells."""
    rows = np.indices((_H, _W))[0]
    below = np.clip((rows - 74) / 12.0, 0.0, 1.0)
    return np.where((rows >= 74) & (np.abs(np.arange(_W) - 75) <= 18)[None, :], depth + (1 - depth) * below, 1.0)


def test_the_objects_shadow_left_beside_the_hole_is_repainted_not_continued() -> None:
    """The relighting left the object's soft shadow darker than its floor (a box proxy for an
    armchair), its shades those of the darker planks and seams found all around: the fill must
    not copy it nor continue it inward, so it is repainted as context. (Before the rule: 68 % of
    its cells exemplar, 32 % repainted.)"""
    shade = _shade(0.6)
    image, shadow = _wood(np.random.default_rng(11)) * shade[..., None], shade < 0.7
    hole = _hole()
    got = border_material(image, ~hole, hole, min_cells=64)
    assert got.source == "border material"
    # a shadow on the bright planks and across their seams is not all told apart by its level
    assert (got.exemplar & shadow).sum() < 0.45 * shadow.sum()
    assert got.replaced[shadow].mean() > 0.45
    assert (got.exemplar & ~hole & ~shadow).sum() > 0.8 * (~hole & ~shadow).sum()


def test_a_fine_print_as_dark_beside_the_hole_is_no_shadow() -> None:
    """Paint is told from shade by its edges: on a plain floor, a print of one-cell stripes as
    dark as the shadow, in the floor's hue and touching the hole, is not taken for it; the soft
    shadow is."""
    hole = _hole()
    floor = np.array([0.45, 0.30, 0.18]) * (1 + 0.03 * np.random.default_rng(12).standard_normal((_H, _W, 1)))
    for depth, printed in ((1.0, True), (0.4, False)):
        shade = _shade(depth)
        print_ = np.zeros((_H, _W), bool)
        print_[74:84, 57:94] = printed
        image = floor * np.where(print_ & (np.arange(_W) % 2 == 0)[None, :], 0.4, shade)[..., None]
        log_y = log_luminance(image)
        mean = colour_features(image, log_y, ~hole, radius=1)
        halo, _, _ = _shadow_halo(mean, log_y, ~hole, ~hole & (shade == 1) & ~print_ & dilate(hole, 16), hole, 8,
                                  brightened=~hole)
        if printed:
            assert not halo[print_].any()
        else:
            assert halo[(shade < 0.7) & dilate(hole, 8)].mean() > 0.9


def test_a_shadow_takes_the_colours_along_its_surfaces_and_its_surfaces_bounced() -> None:
    """The light left in a shadow is the surface's own, bounced: a warm floor's shadow is more
    saturated than the floor, up to the floor's colour squared; or, where the object holds back
    a warm light and leaves a cooler one, less saturated by as much. It is not another hue."""
    rgb = np.array([0.45, 0.30, 0.18])
    chroma = lambda x: (x / x.sum())[:2]  # noqa: E731
    floor = chroma(rgb)
    cells = np.array([[floor, chroma(rgb**1.5), chroma(rgb**2), chroma(rgb**0.5), chroma(rgb[::-1]),
                       chroma(np.array([0.30, 0.45, 0.18])), chroma(rgb**3.5)]])
    assert _shadow_colours(cells, floor).tolist() == [[True, True, True, True, False, False, False]]


def _footprint() -> np.ndarray:
    """How coarsely a panorama resolves each cell of a floor seen from above its left edge:
    finest there, coarser with the distance."""
    return np.broadcast_to(1.0 + (np.arange(_W) / 40) ** 2, (_H, _W))


def test_cells_resolved_far_more_coarsely_than_the_hole_are_not_copied() -> None:
    hole, known = _hole(), ~_hole()
    footprint = _footprint()
    limit = 2 * np.median(footprint[hole])
    got = sharp_exemplar(known, footprint, hole)
    assert got.any() and not (got & ~known).any()
    assert (footprint[got] <= limit).all()
    # all the cells within that resolution stay, those beside the hole among them
    assert np.array_equal(got, known & (footprint <= limit))
    assert got[hole.nonzero()[0].min(), hole.nonzero()[1].max() + 1]


def test_where_few_cells_are_as_sharp_the_finest_twice_the_holes_are_kept() -> None:
    hole = _hole()
    known = np.zeros_like(hole)
    known[:, 130:] = True  # seen only far beyond the hole, all of it coarser than twice the hole's
    footprint = _footprint()
    got = sharp_exemplar(known, footprint, hole)
    assert got.sum() >= 2 * hole.sum() and got.sum() < known.sum()
    assert footprint[got].max() <= footprint[known & ~got].min()
    # a small exemplar is kept whole
    few = known & (np.arange(_H) < 10)[:, None]
    assert np.array_equal(sharp_exemplar(few, footprint, hole), few)
