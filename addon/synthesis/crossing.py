"""A band that crosses the hole: a painted lane, a strip of another floor between two.

The exemplar of the hole's material (`material`) leaves out what is seen on few sides of the hole,
which keeps clutter out but also stops a lane wider than a line at the hole's border, with the
floor on its far side filled as the near side's. Read around the hole, such a band shows as a
pattern of colours that nothing else makes: one side's material, the band, the other side's
material, the band again. The two places where it meets the hole are joined by a straight strip
of their width, and the hole's pieces on either side take their own side's material. Each piece
and the strip are synthesised from the cells of their own colour around the hole; the strip is
brought to the level of its colour at its border, each piece to that of its side (`fill_crossing`).

The colours are read with their texture, the contrast of luminance around each cell: a rug's black
and white stripes average to the wood's colour, but not to its texture. With the same material on
both sides (or no one material on a side), a band is continued only where it lines up across the
hole: its two places at the border equally placed across the line joining them, and seen running
on straight away from the hole past one of them. A band much darker than that material is not:
two feet or legs of one thing, in line on two sides, end under the object as often as they cross.
A stripe that does not line up is left to the material's fill: nothing tells whether it crosses
or ends under the object.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DimredError
from ..light.radiosity import LUMA
from ..segmentation.masks import box_mean, components, dilate
from .material import colour_features, direction_bins, log_luminance, log_spread, ring_widths
from .structure import Filled
from .texture import CancelFn, SynthesisParams, fill_with_sources, membrane

# Colour features: log luminance over 0.3, chromaticity (r, g) over 0.03, and the spread of log
# luminance over 0.1 (all over 5x5 cells). Light printed on a photographed floor changes its
# luminance across the hole far more than its chromaticity. The spread tells a rug's stripes from
# the wood they average to (photo-textured hotel_rug_box at 512x256: 0.3-0.5 against 0.02-0.05).
_SCALE = np.array([0.3, 0.03, 0.03, 0.1])
_CLUSTERS = 6  # colours looked for around the hole before near ones are merged
_MERGE = 3.0  # feature distance below which two colours are one
_BINS = 72  # directions the border is read in
_ANNULUS = 4  # cells past the contact band where the border is read
# Directions a band's crossing of the border spans at most, and a side between its two crossings
# at least. A stool's legs reaching through a rug make the hole's border meet the band in wide
# runs with a narrow side between them, beyond it (photo-textured hotel_rug_stool at 512x256: runs
# of 14 and 9 directions, 8 between): at a sixth and a sixth that rug was filled with the wood and
# the bed around it (mean error 0.42-0.45 over seeds 0-3), at a quarter and a ninth it runs on
# (0.12-0.14), the other photo truths and floor scenes unchanged. A side narrower still is a
# band's own edge read as a colour of its own (the texture's spread is high along it).
_MAX_BAND = _BINS // 4
_MIN_SIDE = _BINS // 9
_SIDE_SHARE = 0.7  # share of a side's directions its material must hold
# Directions in which the border must be seen for its sides to be read. Where part of it is not
# (the raster's edge, a wall, something else in front), a side may lie in the gap, and a colour
# seen on two sides of the gap may be one region, interrupted: there a band is a colour other than
# the ring's commonest that meets the border in two runs of at most a third of the directions,
# something seen between them both ways round, lined up across the hole. The rug under
# photo-textured hotel_rug_middle_box, whose floor reaches the raster's edge (79 % of the
# directions seen), meets it in runs of 19 and 9 directions with 7 of wood between them: at
# 512x256 its total 0.386 -> 0.344, mean error 0.063 -> 0.021, detail 0.23 -> 0.94. Its wood,
# read as a band between two other colours, would be continued across hotel_chair's hole, which
# the raster's edge cuts too.
_SEEN_SHARE = 0.9
_MAX_UNSEEN_BAND = _BINS // 3
_LEVEL_RADIUS = 2  # cells: the mean a region's level is read from around the hole
# A side's level is read from its own colour and from each other colour that holds this share of
# the cells within `_BESIDE` of it (the band's left out): light printed on the floor splits one
# wood into a bright colour and a dark one, and a piece that takes the bright one would carry it
# over the whole piece (photo-textured hotel_rug_box at 512x256: the wood below the rug 10-37 %
# bright, mean error 0.08 -> 0.03; the dark wood held 49 % of the cells beside it). A colour
# holding less is a patch or a thing beside the piece, whose level must not spread into it: a
# white spot beside the green floor of a workshop, the dark print of a chair's shadow on the
# hotel's wood (up to 24 % in both held-out scenes where all colours were read: totals worse by
# 0.033 and 0.063).
_SIDE_COLOUR = 1 / 3
_BESIDE = 4
_GRAIN_RADIUS = 3  # cells: the synthesis's grain is its luminance over its mean over this square
# A band with one material on both sides: the share of the two places' extents across the line
# joining them that both hold, and the share of the cells past one place, within the ring's reach
# and its extent, that must be of the band (at least half of them seen).
_OVERLAP = 0.5
_RUNS_ON = 0.6
_FEET = 4.0  # times darker than the material on both its sides: no band, but feet or legs


@dataclass(frozen=True)
class Crossing:
    """`regions` (h, w): per hole cell the colour label it takes (-1 elsewhere); `labels` (h, w)
    the colour label of the known cells near the hole (-1 elsewhere); `band` the band's label."""

    regions: np.ndarray
    labels: np.ndarray
    band: int

    @property
    def band_cells(self) -> int:
        """The hole cells of the band's strip."""
        return int((self.regions == self.band).sum())


def find_crossing(image: np.ndarray, known: np.ndarray, hole: np.ndarray) -> Crossing | None:
    """The band that crosses `hole` in `image` (h, w, 3 reflectance; `known` the cells seen), or
    None where the colours around the hole show none."""
    known = known & ~hole
    if not hole.any() or not known.any():
        return None
    reach, contact = ring_widths(hole)
    near = known & dilate(hole, 2 * reach)
    ring = known & dilate(hole, reach) & ~dilate(hole, contact)
    if ring.sum() < _CLUSTERS * 8:
        return None
    annulus = ring & dilate(hole, contact + _ANNULUS)
    centre = tuple(float(x.mean()) for x in np.nonzero(hole))
    directions = direction_bins(*np.indices(hole.shape), centre, _BINS)
    partial = (_border_sequence(annulus.astype(np.int64) - 1, annulus, directions) >= 0).mean() < _SEEN_SHARE
    log_y = log_luminance(image)
    colour = colour_features(image, log_y, known, radius=2)

    def textured() -> np.ndarray:
        spread = log_spread(log_y, known, colour[..., 0], radius=2)
        return np.concatenate([colour, spread[..., None]], axis=-1) / _SCALE

    # Colour alone first: along every edge between two colours the spread is high too, and there
    # it reads as a colour of its own. The texture is read only where colour finds no band.
    for read in (lambda: colour / _SCALE[:3], textured):
        features = read()
        labels = np.full(hole.shape, -1)
        labels[near] = _colour_labels(features[ring], features[near])
        found = _lined_up_band(labels, colour, hole, ring=ring, near=near, annulus=annulus,
                               directions=directions, reach=reach, partial=partial)
        if found is not None:
            break
    else:
        return None
    band, ends = found
    regions = np.full(hole.shape, -1)
    regions[_strip(hole, *ends)] = band
    pieces, count = components(hole & (regions < 0))
    for piece in range(count):
        cells = pieces == piece
        beside = labels[annulus & dilate(cells, contact + _ANNULUS + 1)]
        beside = beside[(beside >= 0) & (beside != band)]
        if not len(beside):
            return None  # a piece with no colour beside it: nothing to say what it continues
        regions[cells] = np.bincount(beside).argmax()
    return Crossing(regions=regions, labels=labels, band=band)


def _lined_up_band(labels: np.ndarray, colour: np.ndarray, hole: np.ndarray, *, ring: np.ndarray,
                   near: np.ndarray, annulus: np.ndarray, directions: np.ndarray,
                   reach: int, partial: bool) -> tuple[int, list[np.ndarray]] | None:
    """The band among `labels` read around `hole` (`_band`; `_unseen_band` where the border is
    `partial`ly seen) and its cells where it meets the hole on each side, or None where none is
    found, its cells there are too few to place it or differ in chromaticity from one side to the
    other (`colour`: log luminance and chromaticity, each cell's local mean), or it has one
    material on both sides (or sides not seen) and is much darker than the commonest material of
    the ring or does not line up across the hole (`_in_line`)."""
    around = _border_sequence(labels, annulus, directions)
    found = _unseen_band(around, np.bincount(labels[ring & (labels >= 0)]).argmax()) if partial else _band(around)
    if found is None:
        return None
    band, runs, apart = found
    inner = ring & dilate(hole, max(reach // 2, 4)) & (labels == band)
    ends = [_run_cells(inner, directions, start, length) for start, length in runs]
    if min(len(e) for e in ends) < 4:
        return None
    # Light printed on the floor may change a band's luminance from one side to the other, not
    # its chromaticity: a sunlit patch and a yellow armchair printed on the floor, smooth and
    # bright both, share a texture's colour (photo-textured hotel_chair at 1024x512: 4.5 apart in
    # chromaticity at the two ends; the bands of the other photo truths 0.4-1.2).
    at_ends = [np.median(colour[tuple(e.astype(np.int64).T)][:, 1:], axis=0) / _SCALE[1:3] for e in ends]
    if np.linalg.norm(at_ends[0] - at_ends[1]) >= _MERGE:
        return None  # two things of one texture, not one band
    if not apart:
        material = np.bincount(labels[ring & (labels >= 0) & (labels != band)]).argmax()
        level = [np.median(colour[..., 0][ring & (labels == label)]) for label in (band, material)]
        if level[0] < level[1] - np.log(_FEET) or not _in_line(labels, near, band, *ends, reach=reach):
            return None
    return band, ends


def fill_crossing(crossing: Crossing, image: np.ndarray, known: np.ndarray, params: SynthesisParams, *,
                  seed: int = 0, cancel: CancelFn | None = None) -> Filled:
    """`image` (h, w, 3) with the crossing's regions filled, each synthesised from the `known`
    cells of its own colour near the hole and brought to the membrane over it of the means (a few
    cells wide) of the cells beside it, its own grain (luminance over its mean) kept: the band's
    own colour's cells, a side's those of its own colour and of each other colour but the band's
    common beside it (`_side_cells`). A region whose colour has too few cells for the synthesis
    (a narrow band's) takes the grain of all the cells seen; one with no such cell beside it, the
    synthesis's level. Raises `DimredError` where too little is seen to synthesise at all."""
    out = np.asarray(image, np.float32).copy()
    sources = np.full((*known.shape, 2), -1, np.int64)
    done = known & ~(crossing.regions >= 0)
    labels = np.unique(crossing.regions[crossing.regions >= 0])
    for label in sorted(labels, key=lambda k: k != crossing.band):  # the band first: the sides meet it
        region = crossing.regions == label
        own = done & (crossing.labels == label)
        try:
            got, src = fill_with_sources(out, done, region, params, exemplar=out, exemplar_valid=own, seed=seed,
                                         cancel=cancel)
        except DimredError:  # too few cells of this colour (a narrow band): the grain of all seen around
            got, src = fill_with_sources(out, done, region, params, seed=seed, cancel=cancel)
        luma = got @ LUMA
        mean, _ = box_mean(luma[..., None], region, _GRAIN_RADIUS)
        grain = luma / np.maximum(mean[..., 0], 1e-9)
        out[region], sources[region] = got[region], src[region]
        beside = own if label == crossing.band else _side_cells(crossing, done, region, label)
        if (beside & dilate(region, 2)).any():
            level, _ = box_mean(out, beside, _LEVEL_RADIUS)
            out[region] = membrane(level, beside, region)[region] * grain[region, None]
        done = done | region
    return Filled(out, sources, None)


def _side_cells(crossing: Crossing, done: np.ndarray, piece: np.ndarray, label: int) -> np.ndarray:
    """(h, w) the `done` cells whose level the `piece` of the hole beside the band (of colour
    `label`) takes: those of its own colour, and of each other colour but the band's that holds
    `_SIDE_COLOUR` of the cells with a colour within `_BESIDE` cells of the piece."""
    labels = np.where(done & dilate(piece, _BESIDE), crossing.labels, -1)
    labels[labels == crossing.band] = -1
    count = np.bincount(labels[labels >= 0])
    side = np.flatnonzero(count >= _SIDE_COLOUR * max(count.sum(), 1))
    return done & np.isin(crossing.labels, np.append(side, label))


def _colour_labels(sample: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """(N,) the label of each of `cells` (N, 3 features): its nearest colour among those k-means
    finds in `sample`, a colour nearer than `_MERGE` to a more common one taken as that one."""
    centres = [np.median(sample, axis=0)]
    for _ in range(_CLUSTERS - 1):  # farthest-point start: the same colours from run to run
        gap = np.min([np.linalg.norm(sample - c, axis=1) for c in centres], axis=0)
        centres.append(sample[np.argmax(gap)])
    centres = np.array(centres)
    for _ in range(20):
        nearest = np.argmin(((sample[:, None] - centres[None]) ** 2).sum(-1), axis=1)
        centres = np.array([sample[nearest == k].mean(axis=0) if (nearest == k).any() else centres[k]
                            for k in range(len(centres))])
    # A colour joins the most common one near it, not a chain of near ones: the blends along a
    # band's edges would chain the band to both its sides.
    count = np.bincount(nearest, minlength=len(centres))
    group = np.arange(len(centres))
    commonest = np.argsort(-count, kind="stable")
    for k in commonest:
        roots = [j for j in commonest if group[j] == j and count[j] > count[k]]
        near = [j for j in roots if np.linalg.norm(centres[k] - centres[j]) < _MERGE]
        if near:
            group[k] = near[0]
    group = np.unique(group, return_inverse=True)[1]
    return group[np.argmin(((cells[:, None] - centres[None]) ** 2).sum(-1), axis=1)]


def _border_sequence(labels: np.ndarray, annulus: np.ndarray, directions: np.ndarray) -> np.ndarray:
    """(_BINS,) the commonest label of the `annulus` cells in each direction (-1 where none),
    a direction whose label differs from both its neighbours' taken as its predecessor's."""
    counts = np.zeros((_BINS, labels.max() + 1))
    np.add.at(counts, (directions[annulus], labels[annulus]), 1.0)
    around = np.where(counts.sum(axis=1) > 0, counts.argmax(axis=1), -1)
    before, after = np.roll(around, 1), np.roll(around, -1)
    return np.where((around != before) & (around != after), before, around)


def _runs(around: np.ndarray) -> list[tuple[int, int, int]]:
    """The circular runs of `around`: (label, first direction, length)."""
    starts = np.flatnonzero(around != np.roll(around, 1))
    if not len(starts):
        return [(int(around[0]), 0, len(around))]
    ends = np.roll(starts, -1)
    n = len(around)
    return [(int(around[s]), int(s), int((e - s) % n) or n) for s, e in zip(starts, ends, strict=True)]


def _band(around: np.ndarray) -> tuple[int, list[tuple[int, int]], bool] | None:
    """The label that meets the border in exactly two runs of at most `_MAX_BAND` directions
    between two sides of at least `_MIN_SIDE`, with its runs (first direction, length) and
    whether the sides are held by two different materials (the first such label, else the
    first of any); None where none does."""
    runs = _runs(around)
    found = []
    for label in sorted({r[0] for r in runs if r[0] >= 0}):
        mine = [(s, n) for lab, s, n in runs if lab == label]
        if len(mine) != 2 or max(n for _, n in mine) > _MAX_BAND:
            continue
        if min((b[0] - a[0] - a[1]) % len(around) for a, b in ((mine[0], mine[1]), (mine[1], mine[0]))) < _MIN_SIDE:
            continue
        sides = [_side(around, a, b) for a, b in ((mine[0], mine[1]), (mine[1], mine[0]))]
        found.append((label, mine, None not in sides and sides[0] != sides[1]))
    return max(found, key=lambda f: f[2], default=None)


def _unseen_band(around: np.ndarray, material: int) -> tuple[int, list[tuple[int, int]], bool] | None:
    """The first label but `material` that meets the border in exactly two runs of at most
    `_MAX_UNSEEN_BAND` directions with something seen between them both ways round, with its runs
    (first direction, length) and False: its sides are not read; None where none does."""
    runs = _runs(around)
    for label in sorted({r[0] for r in runs if r[0] >= 0 and r[0] != material}):
        mine = [(s, n) for lab, s, n in runs if lab == label]
        if len(mine) != 2 or max(n for _, n in mine) > _MAX_UNSEEN_BAND:
            continue
        sides = (_between(around, mine[0], mine[1]), _between(around, mine[1], mine[0]))
        if all((side >= 0).any() for side in sides):  # else one region that the gap interrupts
            return label, mine, False
    return None


def _between(around: np.ndarray, run: tuple[int, int], next_run: tuple[int, int]) -> np.ndarray:
    """The labels of `around` in the directions between `run`'s end and `next_run`'s start."""
    first = run[0] + run[1]
    return around[np.arange(first, first + (next_run[0] - first) % len(around)) % len(around)]


def _side(around: np.ndarray, run: tuple[int, int], next_run: tuple[int, int]) -> int | None:
    """The label holding `_SIDE_SHARE` of the directions between `run`'s end and `next_run`'s start."""
    side = _between(around, run, next_run)
    seen = side[side >= 0]
    if not len(seen):
        return None
    count = np.bincount(seen)
    return int(count.argmax()) if count.max() >= _SIDE_SHARE * len(seen) else None


def _run_cells(cells: np.ndarray, directions: np.ndarray, start: int, length: int) -> np.ndarray:
    """(N, 2) the `cells` in the directions of a run, a direction of margin on each side."""
    inside = ((directions - start + 1) % _BINS) < length + 2
    return np.argwhere(cells & inside).astype(np.float64)


def _axis(first: np.ndarray, second: np.ndarray
          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, float] | None:
    """The line from the mean of the cells `first` (N, 2) to that of `second`: its two ends, the
    unit vectors along and across it, and its length; None where the two means coincide."""
    a, b = first.mean(axis=0), second.mean(axis=0)
    length = float(np.linalg.norm(b - a))
    if length < 1e-9:
        return None
    along = (b - a) / length
    return a, b, along, np.array([-along[1], along[0]]), length


def _across(cells: np.ndarray, across: np.ndarray) -> tuple[float, float]:
    """How far `cells` (N, 2) reach along the unit vector `across` (5th and 95th percentiles)."""
    lo, hi = np.percentile(cells @ across, [5, 95])
    return float(lo), float(hi)


def _in_line(labels: np.ndarray, near: np.ndarray, band: int, first: np.ndarray, second: np.ndarray, *,
             reach: int) -> bool:
    """Whether the `band` cells where it meets the hole on one side (`first`, (N, 2)) and on the
    other (`second`) line up across it: their extents across the line joining them overlapping by
    `_OVERLAP` of both together, and the band running on straight away from the hole past one of
    them (`_RUNS_ON` of the `near` cells of `labels` within `reach` past it and within its extent)."""
    axis = _axis(first, second)
    if axis is None:
        return False
    a, b, along, across, _ = axis
    cells, seen = np.argwhere(near), labels[near]
    offset = cells @ across
    extents, runs_on = [], []
    for end, at_end, outward in ((a, first, -along), (b, second, along)):
        lo, hi = _across(at_end, across)
        past = (cells - end) @ outward
        corridor = (past > 0) & (past <= reach) & (offset >= lo) & (offset <= hi)
        extents.append((lo, hi))
        runs_on.append(corridor.sum() >= 0.5 * reach * max(hi - lo, 1.0)
                       and (seen[corridor] == band).mean() >= _RUNS_ON)
    (lo0, hi0), (lo1, hi1) = extents
    overlap = (min(hi0, hi1) - max(lo0, lo1)) / max(max(hi0, hi1) - min(lo0, lo1), 1e-9)
    return overlap >= _OVERLAP and any(runs_on)


def _strip(hole: np.ndarray, first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """(h, w) the hole cells of the straight strip joining the band's cells where it meets the
    hole on one side (`first`, (N, 2)) to the other's, its width measured across it at each end
    and interpolated between."""
    axis = _axis(first, second)
    if axis is None:
        return np.zeros_like(hole)
    a, _, along, across, length = axis
    offsets, widths = [], []
    for cells in (first, second):
        lo, hi = _across(cells, across)
        offsets.append(0.5 * (lo + hi) - a @ across)
        widths.append(hi - lo)
    rows, cols = np.nonzero(hole)
    q = np.stack([rows, cols], axis=1) - a
    t = np.clip(q @ along / length, 0.0, 1.0)
    centre = offsets[0] * (1 - t) + offsets[1] * t
    half = 0.5 * (widths[0] * (1 - t) + widths[1] * t)
    out = np.zeros_like(hole)
    out[rows, cols] = np.abs(q @ across - centre) <= half
    return out
