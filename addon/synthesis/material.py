"""Which of a surface's seen cells are of the material the hole lies in: the exemplar.

A proxy's floor is whatever the artist modelled, but the photograph shows on it a rug, a desk's
foot, the object's own legs and contact shadow. Copied into the hole they are the fill's worst
failures (a dark bruise, a rug's stripes where there was wood), so the exemplar is restricted to
the cells of the hole's own material.

That material is what surrounds the hole on every side: a colour (log luminance and
chromaticity over 3x3 cells) belongs to it when it occurs in most directions around the hole,
at a distance from it. A checker's two colours, a plank floor's shades and seams, and the blends
between them do; a rug, a bed or a desk's foot on one side does not, nor does the contact shadow
or the legs right at the object. What is wider than a line and of no such colour is left out,
with a cell of margin; beside the hole it is repainted, so that nothing continues it inward.
What is much darker than the band right outside the hole (a desk, a chair's legs, a rug's dark
print) is never copied either, unless its colour too is found all around the hole. Nor is the
object's own shadow where the relighting left it darker than the surface around: it is repainted.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..light.radiosity import LUMA
from ..segmentation.masks import box_mean, box_sum, components, dilate, erode
from .shift_map import hole_extent

# Feature bins: log luminance in steps of 0.15, chromaticity (r, g) in steps of 0.03. A colour is
# near the bins within one step of its own, so two colours up to about 0.3 and 0.06 apart meet:
# about what the eye calls another colour at a glance. Coarser luminance steps let a rug's blends
# pass for wood (photo-textured truths at 512x256, 128 samples: steps of 0.25 and 0.35 raised
# hotel_box's fill mean error from 0.02 to 0.16-0.20 and hotel_rug_box's from 0.08 to 0.17-0.24).
_STEPS = np.array([0.15, 0.03, 0.03])
_SECTORS = 8  # directions around the hole
_CONTACT = 0.05  # of the ring's reach: the band right at the hole left out (its contact shadow)
_MIN_SECTOR_CELLS = 16  # cells a direction needs around the hole to count
# Fewer directions or cells around the hole than these tell no material apart from a chance
# patch of light (a 64x32 panorama's floor): the whole surface is the exemplar then.
_MIN_SECTORS = 3
_MIN_RING_CELLS = 400
_PRESENT = 0.01  # share of a direction's cells a colour needs there (at least 2 cells)
_AROUND = (0.75, 0.625, 0.5)  # shares of the counted directions a colour must be present in, strictest first
_RING_MATCH = 0.5  # the share of the ring's outer half that must match for a stricter share to hold
_MIN_BEYOND = 0.01  # share of the seen cells thin things of no material colour must make to be left out
_SCATTER_RADIUS = 3  # cells: most of the known cells this near an exemplar cell must be exemplar too
# A cell (3x3 mean) this many times darker than the median of the band right outside the hole is
# something else lying there (a desk, a chair's legs, a rug's dark print) unless its colour is found
# all around the hole (a checker's dark tiles). The colour bins alone let it in where the hole
# lies at the edge of what is seen: with few directions counted, colours on one side pass the
# relaxed shares. Measured on the photo-textured truths (bench_photo_groundtruth.py, mean error /
# total): at 256x128 hotel_walls 0.347/0.722 -> 0.086-0.186/0.589-0.659 for factors 2.8-6, at
# 512x256 hotel_box 0.120/0.398 -> 0.055-0.076/0.347-0.368; the other scenes within 0.03.
_DARKER = 4.0
_MIN_SHARE_WARN = 0.5  # below this share of the seen cells, the surface is mostly something else
# The object's shadow right beside the hole where the relighting leaves it darker than its surface
# (a box proxy's shadow is not the armchair's): cells joined to the hole, within half the ring,
# through cells darker than `_HALO_DARKER` of the material's median beyond that reach and than
# `_HALO_BELOW` of its `_HALO_QUANTILE` there, in the colours a shadow on it takes
# (`_shadow_colours`), smooth (3x3 deviation of log luminance below `_HALO_SMOOTH`) and brightened
# by the relighting (E' / E above `RELIT`). Continued inward, it made the bottom of the real hotel
# armchair's fill a dark patch (245 cells there, at 0.8-1 times the quantile alike). The
# quantile, the colours and the smoothness tell it from the material or paint: a checker's dark
# tiles are as dark as the material's darkest beyond, and the exact proxy's shadow on them is
# relit to within a few percent (at the quantile itself tile_stool's were taken for shadow, 153
# cells, and its fill without structure rose from 0.171 to 0.203 total error; basic_box's mean
# error from 0.000 to 0.016 at the median's 0.7 alone); a rug's stripes passing under the object
# are crisp (without the chromaticity and smoothness hotel_rug_box's mean error rose from 0.07 to
# 0.38).
_HALO_DARKER = 0.7
_HALO_QUANTILE = 0.05
_HALO_BELOW = 0.85
_HALO_SMOOTH = 0.15
RELIT = 1.05  # E' / E above this: the relighting brightens the cell, beyond the room's general gain
# Cells the panorama resolves far more coarsely than the hole (the floor beyond it, seen at a
# more grazing angle) hold the texture blurred and stretched along the rays, and on a glossy
# floor another sheen: copied cell by cell into the hole near the probe they made the real
# lobby's bench a pale smear. The per-pixel synthesis copies only the cells resolved at most
# `_COARSER` times as coarsely as the hole's median cell, or, where fewer are, the `_SHARP_MIN`
# times the hole's cells that are resolved the finest. On the photo-textured truths at 512x256
# (16, 64 and 128 samples) the fills' mean errors summed 2.25 without it, 2.18 with it
# (apartment_chair at 64 samples 0.049 -> 0.021, warehouse_box 0.026 -> 0.002, hotel_rug_box at
# 128 0.080 -> 0.060; apartment_chair at 16 0.046 -> 0.055); 1.5 times summed 2.37, 3 times
# changed nothing. The shifted copies of a tiling are read from the photograph itself and keep
# every cell: cut to the sharp ones, a checker under a box proxy 5 % small lost its repeat and
# was drawn as plank lines (bench_rough_proxies, basic_box at scale 0.95: ghost 0.07 -> 0.61).
_COARSER = 2.0
_SHARP_MIN = 2.0


@dataclass(frozen=True)
class Material:
    """The known cells of the hole's material (`exemplar`), the other known cells near the hole
    that the fill repaints as context (`replaced`), and what the exemplar is: `source`
    'border material', 'whole surface' where too few cells match, or 'wall columns' (a wall's
    every seen cell, continued along its columns: `wall_material`)."""

    exemplar: np.ndarray
    replaced: np.ndarray
    source: str
    share: float  # exemplar cells / known cells
    decided: bool = True  # False: too little is seen around the hole to tell its material
    # of `replaced`, the object's shadow left darker than the material; the cells past it that
    # are its penumbra (`_shadow_halo`); the material's cells around the hole it was judged
    # against; and the cells near the hole in the colours of the material's shadows that are
    # not in the shadow (the floor beside it, exemplar or not); None where the material is not
    # told by its border
    shadow: np.ndarray | None = None
    penumbra: np.ndarray | None = None
    around: np.ndarray | None = None
    beside: np.ndarray | None = None

    @property
    def mostly_other(self) -> bool:
        """Most of the surface seen around the hole is of another material (clutter, a rug), or
        none of it matches."""
        return self.decided and (self.source == "whole surface" or self.share < _MIN_SHARE_WARN)


def border_material(image: np.ndarray, known: np.ndarray, hole: np.ndarray, *, min_cells: int,
                    relit: np.ndarray | None = None) -> Material:
    """The cells of `image` (h, w, 3 reflectance) among `known` whose material surrounds `hole`;
    the whole of `known` where fewer than `min_cells` match. `relit` (h, w): the relighting's own
    change of light on each cell (E' / E), which tells the object's shadow from a surface's
    darkening by something else (`_shadow_halo`); without it every cell counts as relit."""
    undecided = Material(exemplar=known, replaced=np.zeros_like(known), source="whole surface", share=1.0,
                         decided=False)
    if not hole.any():
        return undecided
    reach, contact = ring_widths(hole)
    near = dilate(hole, reach) & ~hole
    inner = dilate(hole, reach // 2)
    if not (known & near).any():
        return undecided
    log_y = log_luminance(image)
    mean = colour_features(image, log_y, known, radius=1)
    bins = np.floor(mean / _STEPS).astype(np.int64)
    lo = bins[known].min(axis=0)
    shape = tuple(bins[known].max(axis=0) - lo + 1)
    flat = np.ravel_multi_index(tuple(np.moveaxis(np.clip(bins - lo, 0, np.array(shape) - 1), -1, 0)), shape)
    centre = tuple(float(x.mean()) for x in np.nonzero(hole))
    # The band right outside the hole (past its contact shadow) decides first, where one material
    # surrounds the hole there: farther out, the clutter beside a hole (a rug, a desk chair's foot)
    # can fill most directions. The ring beyond adds its colours found all round too (the light
    # printed on a photographed floor shifts its shade from the band to the ring). A hole across
    # several materials (a painted line between two floors) matches none all round in the band:
    # the ring beyond decides alone then, with the band (the contact shadow, the legs) left out.
    rings = ((known & inner & ~dilate(hole, contact), _AROUND[:1]),
             (known & near & ~inner, _AROUND))
    found, last = [], None
    everywhere = np.zeros_like(known)  # colours found all around the hole, in either ring
    for ring, shares in rings:
        directions = _directions(flat, shape, ring, centre)
        if directions is None:
            continue
        everywhere |= directions >= _AROUND[0]
        # A floor's light and gloss change its colour from one side of the hole to the other: where
        # too little of the ring matches colours found all around it, colours found in fewer
        # directions are taken too, down to half of them (a rug on one side stays out).
        for share in shares[:1] if found else shares:
            last = (known & (directions >= share), ring)
            if (last[0] & ring).sum() >= _RING_MATCH * ring.sum():
                found.append(last)
                break
    if last is None:
        return undecided
    matching, around = (np.logical_or.reduce([m for m, _ in found]), np.logical_or.reduce([r for _, r in found])
                        ) if found else last
    # Cells between a texture's colours (a tile's edge, a seam) may match nothing on their own:
    # only what is wider than a line counts as something else, with a cell of margin around it,
    # unless a cell is darker or brighter than any of the material's (a rug's black stripe).
    lo, hi = np.quantile(log_y[matching & around], [0.005, 0.995]) if (matching & around).any() else (0.0, 0.0)
    beyond = known & ~matching & ((log_y < lo - _STEPS[0]) | (log_y > hi + _STEPS[0]))
    beyond &= box_sum(beyond, 1) >= 3  # a stripe or a spot, not a pixel of noise
    if beyond.sum() < _MIN_BEYOND * known.sum():
        # a few odd cells would be copied nowhere visible, but leaving them out breaks the lines
        # the planks' structure draws between their visible ends
        beyond[:] = False
    wide = dilate(dilate(erode(known & ~matching, 1), 1), 1) & known
    dark = _dark_clutter(mean[..., 0], known & ~everywhere, rings[0][0] if rings[0][0].any() else known)
    # left out with a cell of margin but not repainted: the colour bins decide what the fill
    # composes anew around the hole
    exemplar = known & ~wide & ~(dilate(beyond | dark, 1) & known)
    # and not scattered in something else (a rug's stripes whose blends pass for wood)
    nearby, _ = box_mean(exemplar[..., None].astype(np.float64), known, _SCATTER_RADIUS)
    exemplar &= nearby[..., 0] >= 0.5
    # the material around the hole the object's shadow is judged against: beyond half the ring
    # where it is seen there
    around = exemplar & rings[1][0]
    around = around if around.any() else exemplar & near
    brightened = known if relit is None else known & (relit > RELIT)
    halo, penumbra, beside = _shadow_halo(mean, log_y, known, around, hole, reach // 2, brightened=brightened)
    exemplar &= ~dilate(halo, 1)
    if exemplar.sum() < min_cells:
        return replace(undecided, decided=True)
    # Only what is wider than a line is repainted beside the hole: a thin stripe is only left out.
    return Material(exemplar=exemplar, replaced=(near & wide) | halo, source="border material",
                    share=float(exemplar.sum() / known.sum()), shadow=halo, penumbra=penumbra, around=around,
                    beside=beside)


def ring_widths(hole: np.ndarray) -> tuple[int, int]:
    """The cells around `hole` (non-empty) whose colours tell its material: how far the ring
    reaches (half the hole's extent, 4-32 cells), and how wide its contact band is (the object's
    contact shadow and legs, right at the hole), which is left out."""
    reach = int(np.clip(round(hole_extent(hole) / 2), 4, 32))
    return reach, max(1, round(_CONTACT * reach))


def log_luminance(image: np.ndarray) -> np.ndarray:
    """(h, w) the log luminance of `image` (h, w, 3), from 1e-4 up."""
    return np.log(np.maximum(image @ LUMA, 1e-4))


def colour_features(image: np.ndarray, log_y: np.ndarray, known: np.ndarray, *, radius: int) -> np.ndarray:
    """(h, w, 3) `log_y` (`log_luminance` of `image`) and the chromaticity (r, g) of `image`, each
    the mean over the `known` cells within `radius`."""
    chroma = image[..., :2] / np.maximum(image.sum(axis=-1, keepdims=True), 1e-6)
    mean, _ = box_mean(np.concatenate([log_y[..., None], chroma], axis=-1), known, radius)
    return mean


def log_spread(log_y: np.ndarray, known: np.ndarray, mean: np.ndarray, *, radius: int) -> np.ndarray:
    """(h, w) the standard deviation of `log_y` (log luminance) over the `known` cells within
    `radius`, about their `mean` (h, w: `colour_features`' first, at the same radius): how much
    contrast a texture holds there."""
    square, _ = box_mean((log_y**2)[..., None], known, radius)
    return np.sqrt(np.maximum(square[..., 0] - mean**2, 0.0))


def direction_bins(rows: np.ndarray, cols: np.ndarray, centre: tuple[float, float], count: int) -> np.ndarray:
    """The direction (0..count-1) in which each cell (rows, cols) lies seen from `centre`."""
    return ((np.arctan2(rows - centre[0], cols - centre[1]) + np.pi) / (2 * np.pi) * count).astype(np.int64) % count


def sharp_exemplar(exemplar: np.ndarray, footprint: np.ndarray, fill: np.ndarray) -> np.ndarray:
    """(h, w) the `exemplar` cells that the panorama resolves at most `_COARSER` times as coarsely
    (`footprint`, h, w, in any unit) as the median of the `fill` cells; where fewer are, the
    `_SHARP_MIN` times as many as the fill's cells resolved the finest (the whole exemplar where
    it is no larger)."""
    count = int(exemplar.sum())
    if not count or not fill.any():
        return exemplar
    limit = _COARSER * float(np.median(footprint[fill]))
    keep = min(count, int(_SHARP_MIN * fill.sum()))
    if (exemplar & (footprint <= limit)).sum() < keep:
        limit = float(np.partition(footprint[exemplar], keep - 1)[keep - 1])
    return exemplar & (footprint <= limit)


def wall_material(known: np.ndarray) -> Material:
    """A wall's exemplar: every `known` cell, nothing repainted. What stands on a wall beside the
    hole (a door, its frame) is continued into it along the wall's columns (`wall_columns`)."""
    return Material(exemplar=known, replaced=np.zeros_like(known), source="wall columns", share=1.0)


def _dark_clutter(log_y: np.ndarray, candidates: np.ndarray, band: np.ndarray) -> np.ndarray:
    """(h, w) the `candidates` whose `log_y` (log luminance, 3x3 mean) is `_DARKER` times below the
    median over `band` (the cells right outside the hole, mostly its material whatever lies on
    one side of it). A factor, not a spread: the band's spread is clutter's as much as the
    material's (a plain floor's band gave a spread of 0.19, one with a chair's legs 0.74)."""
    return candidates & (log_y < np.median(log_y[band]) - np.log(_DARKER))


def _shadow_halo(mean: np.ndarray, log_y: np.ndarray, known: np.ndarray, material: np.ndarray, hole: np.ndarray,
                 reach: int, *, brightened: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(h, w) the `known` cells within `reach` of `hole` joined to it through cells of the
    object's shadow left darker than the `material` cells (the caller's, beyond `reach` where it
    sees any there): `mean` (`colour_features`) below `_HALO_DARKER` of their median and
    `_HALO_BELOW` of their `_HALO_QUANTILE`, in the colours their shadow takes
    (`_shadow_colours`), smooth (`log_y`: log luminance) and brightened by the relighting
    (`brightened`, h, w): a floor darkened by a wall beside it takes a shadow's colours too, but
    the object's removal does not change its light. The fill is not to continue it. And (h, w)
    its penumbra: the cells within `reach` past it, in those colours, smooth, brightened and
    below the median. And (h, w) the cells in those colours within twice `reach` of the hole that
    are neither, nor darker than the shadow's bound: the floor beside the shadow, which the
    material's cells may not be (a glossy floor's nearer side, more saturated, is not found all
    around the hole)."""
    if not material.any():
        return np.zeros_like(hole), np.zeros_like(hole), np.zeros_like(hole)
    levels = mean[..., 0][material]
    level = min(np.median(levels) + np.log(_HALO_DARKER), np.quantile(levels, _HALO_QUANTILE) + np.log(_HALO_BELOW))
    alike = known & _shadow_colours(mean[..., 1:], np.median(mean[..., 1:][material], axis=0)) & (
        log_spread(log_y, known, mean[..., 0], radius=1) < _HALO_SMOOTH)
    shade = alike & brightened & dilate(hole, reach) & (mean[..., 0] < level)
    labels, _ = components(shade | hole)
    halo = shade & np.isin(labels, np.unique(labels[hole]))
    # its penumbra: the cells past it, as far again, in its colours, smooth, brightened and darker
    # than the median
    below = mean[..., 0] < np.median(levels)
    penumbra = alike & brightened & dilate(halo, reach) & ~halo & below if halo.any() else halo
    beside = alike & dilate(hole, 2 * reach) & ~halo & ~penumbra & (mean[..., 0] >= level)
    return halo, penumbra, beside


def _shadow_colours(chroma: np.ndarray, material: np.ndarray) -> np.ndarray:
    """(h, w) bool: whether each chromaticity (r, g) of `chroma` (h, w, 2) is one a shadow on a
    surface of chromaticity `material` (2,) takes, within one step.

    The light left in a shadow is mostly what the surface around it reflects into it, so it
    comes in the surface's colour after one more bounce (its rgb squared) as well as in the
    light's: the shadow's chromaticity lies between the surface's and that of the surface's
    colour times itself. On a warm wood floor it is more saturated than the floor: the real
    lobby bench's residual shadow under its box proxy has r 0.53-0.55 against the floor's
    0.48-0.50, and within one step of the floor's chromaticity alone 8 of its cells passed for
    shadow (1.5 % of the hole's border, too few to lift). Where the object holds back one light
    and leaves another of a colour farther from the surface's (a warm lamp's shadow lit by a
    window), the shadow is less saturated than the surface instead: its chromaticity lies as far
    on the other side of the surface's, along the same line. The real hotel armchair's shadow
    beside its front right leg has r 0.395 against the floor's 0.442 (its colour squared 0.548),
    and stayed a dark patch beside the fill."""
    rgb = np.append(material, 1.0 - material.sum())
    bounced = (rgb**2 / max(float((rgb**2).sum()), 1e-12))[:2] - material
    t = np.clip(((chroma - material) @ bounced) / max(float(bounced @ bounced), 1e-12), -1.0, 1.0)
    return np.abs(chroma - material - t[..., None] * bounced).max(axis=-1) < _STEPS[1]


def _directions(flat: np.ndarray, shape: tuple[int, ...], ring: np.ndarray, centre: tuple[float, float]
                ) -> np.ndarray | None:
    """(h, w) per cell, the share of the directions around `centre` (those with cells enough of
    `ring`) in which its colour (bin `flat` (h, w) of a grid of `shape`) is present in `ring`;
    None where the ring covers too few directions or cells to tell a material apart."""
    rows, cols = np.nonzero(ring)
    sector = direction_bins(rows, cols, centre, _SECTORS)
    counts = np.zeros((int(np.prod(shape)), _SECTORS))
    np.add.at(counts, (flat[rows, cols], sector), 1.0)
    per_sector = counts.sum(axis=0)
    counted = per_sector >= _MIN_SECTOR_CELLS
    if counted.sum() < _MIN_SECTORS or per_sector.sum() < _MIN_RING_CELLS:
        return None
    present = _neighbour_sum(counts.reshape(*shape, _SECTORS)).reshape(-1, _SECTORS) >= np.maximum(
        _PRESENT * per_sector, 2.0)
    return ((present & counted).sum(axis=1) / counted.sum())[flat]


def _neighbour_sum(counts: np.ndarray) -> np.ndarray:
    """`counts` (a, b, c, k) summed over the bins within one step along each of the first three axes."""
    out = counts.copy()
    for axis in range(3):
        padded = np.pad(out, [(1, 1) if a == axis else (0, 0) for a in range(4)])
        n = out.shape[axis]
        out = (padded.take(range(n), axis=axis) + padded.take(range(1, n + 1), axis=axis)
               + padded.take(range(2, n + 2), axis=axis))
    return out
