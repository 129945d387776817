"""Structure first: a hole on a tiled or planked plane composed from shifted copies of the
visible floor, so that its lines run on in phase, with the seam at the hole's border blended.

The labels of a shift map (`shift_map`) are a tiling's repeats (`translations`), or, on planks
that repeat along no second direction, those translations and shifts along the floor's axes.
The step left between the copies and the known pixels along the border is taken to zero by a
membrane over the hole (the gradient-domain blend of Poisson image editing, whose guidance
field is the copies' own gradients), which also keeps the fill's mean on its surroundings where
the copies came from darker or lighter tiles. On planks, whose hidden stretches no copy shows
(each plank has its own shade and grain), each line along them is interpolated between its two
visible ends instead (`lines`), and the copies give only the photograph's fine detail. A
stochastic texture (carpet, concrete) has no dominant translation and matches itself along no
axis: `structure_fill` returns None and the order-independent synthesis fills it alone.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..segmentation.masks import dilate
from .lines import interpolate_lines
from .material import colour_features, log_luminance, ring_widths
from .shift_map import NEIGHBOURS4, ShiftMap, candidate_shifts, hole_extent, lattice_shifts, shift_map
from .texture import CancelFn, ProgressFn, SynthesisParams, clip_outliers, fill_with_sources, membrane
from .translations import DOMINANT, Translations, dominant_translations, relative_difference

_TRANSLATIONS = 8  # of the texture's repeats, the best this many are labels (time grows with labels^2)
_SHORT_SHIFTS = (2, 4, 8)  # cells: what a plank changes by along its length and across it
_PLANK_ANISOTROPY = 0.8  # planks: the texture changes along one axis at most this share of across it
_LINE_ENDS = 6  # cells averaged at each visible end of a line along the planks (3: -0.02-0.07 in structure)
# The copies' detail finer than the raster, on planks whose profile is not found, over the lines
# sharpened where they are looked up (`plane_fill._LINE_SHARPENING`; with the profile,
# `plane_fill._PROFILED_DETAIL`): on six plank floors at 1024x512 (16 and 64 samples)
# the detail ratio was 0.77-1.09 with weight 0.8, 0.80-1.12 with 0.9, 0.84-1.16 with 1.0. The
# copies' grain is not the truth's: each 0.1 of weight costs up to 0.01 of structure.
_PLANK_DETAIL = 0.9
# A composition copies whole regions from anywhere the exemplar holds, and the exemplar's colours
# are told with a step's tolerance: on the real hotel it took in the lit side of the olive bed
# (chromaticity g 0.383 against the wood's 0.338). The per-pixel synthesis matches each cell's
# neighbourhood and copied little of it; the shift map of the draft preset, which found a repeat
# there, copied it whole into the hole, an olive blob. Copies whose colours the ring around the
# hole does not show (chromaticity beyond its 1st-99th percentile by `_FOREIGN_MARGIN`) on more
# than `_FOREIGN` of the covered cells continue no surface around the hole: the synthesis fills
# alone. That share was 0.28 there, at most 0.02 on the photo-textured truths (512x256, seeds
# 0-1) and 0 on the ten floor scenes (1024x512). Over the photo-textured truths' draws at 512
# and 1024 wide (16 and 64 samples, seeds 0-2) it changed only hotel_walls' at 1024: their worst
# total error fell from 0.482 to 0.427.
_FOREIGN = 0.1
_FOREIGN_MARGIN = 0.01


@dataclass(frozen=True)
class StructureFill:
    """`image` with the covered hole pixels composed and blended (on planks: interpolated along
    them); `shifts` the shift map behind it (its `image`: what it copied there).
    `detail` weighs the photograph's own detail that a lookup finer than the raster adds to
    `image` there: the copy read from the photograph minus the same copy in the raster
    (`plane_fill`). On planks, `lines` (H, W) are the pixels interpolated along the raster axis
    `along` (by `lines.interpolate_lines`); both None elsewhere."""

    image: np.ndarray
    shifts: ShiftMap
    translations: Translations
    detail: float = 1.0
    along: int | None = None
    lines: np.ndarray | None = None

    @property
    def covered(self) -> np.ndarray:
        return self.shifts.covered


def structure_fill(image: np.ndarray, known: np.ndarray, hole: np.ndarray, *, footprint: np.ndarray | None = None,
                   guide: np.ndarray | None = None, guided: np.ndarray | None = None,
                   seed: int = 0) -> StructureFill | None:
    """The `hole` of `image` (H, W, C) composed from shifted copies of its `known` pixels, or
    None where the texture has no dominant translation, no copy reaches the hole, or the copies
    bring colours the ring around the hole does not show (`_foreign_share`). On planks
    (`_plank_axis`) each line along them is interpolated between its visible ends instead
    (`lines`), the copies giving only their fine detail. `guide` (H, W, C) is what the
    photograph shows at the `guided` hole pixels, which were seen but repainted (`shift_map`).
    `seed` varies the labels (the axis shifts' lengths, or which repeats of a tiling): another
    seed gives another, equally continuous fill."""
    image = np.asarray(image, np.float32)
    known = np.asarray(known, bool) & ~hole
    if known.sum() < hole.sum():  # too little floor seen to tell a repeat from a coincidence
        return None
    translations = dominant_translations(image, known, hole)
    if translations.tiling:
        # combinations of a shift that is no repeat are none either (bench_synthesis's planks, a
        # tiling whose list held such a shift: 0.49 -> 0.66 in structure on the 64 px hole)
        repeats = translations.shifts[translations.contrast <= DOMINANT]
        shifts = lattice_shifts(repeats[:_TRANSLATIONS], image, known, hole, seed=seed)
    else:
        shifts = candidate_shifts(translations.shifts[:_TRANSLATIONS], hole, seed=seed)
        # planks of random shades repeat nothing as a whole, but match themselves along their length
        if not (relative_difference(image, known, hole, shifts) <= DOMINANT).any():
            return None
    composed = shift_map(image, known, hole, shifts, footprint=footprint, guide=guide, guided=guided)
    if not composed.covered.any() or _foreign_share(composed, known, hole) > _FOREIGN:
        return None
    along = _plank_axis(image, known, hole)
    out = image.copy()
    interpolated = np.zeros(hole.shape, bool)
    if along is not None:
        lines = interpolate_lines(image, known, axis=along, ends=_LINE_ENDS)
        interpolated = composed.covered & lines.reached
        out[interpolated] = lines.values[interpolated]
    blended = composed.covered & ~interpolated
    if blended.any():
        values, weight = _border_mismatch(image, known, composed)
        fixed = weight > 0
        correction = membrane(clip_outliers(values, fixed), fixed, blended) if fixed.any() else 0.0
        out[blended] = (composed.image + correction)[blended]
    return StructureFill(image=out.astype(np.float32), shifts=composed,
                         translations=translations, detail=1.0 if along is None else _PLANK_DETAIL,
                         along=along, lines=None if along is None else interpolated)


@dataclass(frozen=True)
class Filled:
    """A raster with its hole filled: `image` (H, W, C); `sources` (H, W, 2) the known pixel
    (row, column) each pixel the order-independent synthesis filled copies, -1 elsewhere; and
    the structure fill where the texture repeats (None where it does not)."""

    image: np.ndarray
    sources: np.ndarray
    structure: StructureFill | None


def fill_structured(image: np.ndarray, known: np.ndarray, hole: np.ndarray, params: SynthesisParams, *,
                    structure: bool = True, footprint: np.ndarray | None = None,
                    guide: np.ndarray | None = None, guided: np.ndarray | None = None, seed: int = 0,
                    progress: ProgressFn | None = None, cancel: CancelFn | None = None,
                    sources: np.ndarray | None = None) -> Filled:
    """`image` with its `hole` filled: composed from shifted copies where the texture repeats
    (with `structure`), the rest by the order-independent synthesis (`texture.fill_with_sources`,
    which raises `DimredError` on too little exemplar); and where each pixel was copied from.
    `guide` at the `guided` hole pixels weighs the copies there (`structure_fill`). The
    synthesis copies only the `sources` among the `known` pixels (default: all of them); all
    of them constrain it.
    `progress(level, preview)` gets the composed image first (level -1) where the synthesis has
    more to do, then the synthesis's levels."""
    # Composed whatever the period of the repeats. Checkers of 17 cells (rotated_world at
    # 256x128) and 24 cells (far_dark_box at 1024x512) came out 0.98 and 0.79 in structure,
    # against 0.95 and 0.67 per pixel. Planks whose wood grain matches itself every 7 cells along
    # them (stool, warm_cylinder at 1024x512) were once left to the synthesis; since the copies
    # are read from the panorama itself they score 0.44 and 0.60 composed, against 0.16 and 0.55
    # per pixel, with less object and shadow error (0.131 and 0.212, against 0.142 and 0.225).
    got = (structure_fill(image, known, hole, footprint=footprint, guide=guide, guided=guided, seed=seed)
           if structure else None)
    rest = hole if got is None else hole & ~got.covered
    if got is not None and not rest.any():
        return Filled(got.image, np.full((*hole.shape, 2), -1, np.int64), got)
    if got is not None and progress is not None:
        progress(-1, got.image)
    start, constraint = (image, known) if got is None else (got.image, known | (hole & ~rest))
    copied = constraint if sources is None else constraint & (sources | ~known)
    out, origin = fill_with_sources(start, constraint, rest, params, exemplar=start, exemplar_valid=copied, seed=seed,
                                    progress=progress, cancel=cancel)
    # the composed pixels constrain the synthesis but are no photograph to read detail from
    photographed = known[np.maximum(origin[..., 0], 0), np.maximum(origin[..., 1], 0)] & (origin[..., 0] >= 0)
    return Filled(out, np.where(photographed[..., None], origin, -1), got)


def _plank_axis(image: np.ndarray, known: np.ndarray, hole: np.ndarray) -> int | None:
    """The raster axis (0: rows, 1: columns) that planks run along, or None where the texture
    around the hole changes as much along one axis as along the other (tiles, carpet). Short
    shifts along planks change little (the seams stay, the grain changes slowly), across them
    much: at 1024x512 the shifts along differed 0.45-0.59 as much as those across on six plank
    floors, 0.97-1.03 on four checkers. The known pixels compared lie within the hole's extent
    of it: a narrower ring can miss a tiling's grout lines along one axis altogether."""
    steps = np.array(_SHORT_SHIFTS)
    shifts = np.concatenate([np.stack([steps, 0 * steps], axis=1), np.stack([0 * steps, steps], axis=1)])
    score = relative_difference(image, known, hole, shifts, ring=hole_extent(hole))
    rows, columns = float(score[:len(steps)].sum()), float(score[len(steps):].sum())
    if not np.isfinite(rows + columns) or min(rows, columns) > _PLANK_ANISOTROPY * max(rows, columns):
        return None
    return 0 if rows < columns else 1


def _foreign_share(composed: ShiftMap, known: np.ndarray, hole: np.ndarray) -> float:
    """The share of the cells `composed` covers whose chromaticity (3x3 mean) lies beyond the
    1st-99th percentile of the `known` cells' around the `hole` (within the ring that tells its
    material) by more than `_FOREIGN_MARGIN`."""
    reach, _ = ring_widths(hole)
    ring = known & dilate(hole, reach)
    if not ring.any():
        return 0.0
    image = composed.image
    chroma = colour_features(image, log_luminance(image), known | composed.covered, radius=1)[..., 1:]
    lo, hi = np.quantile(chroma[ring], [0.01, 0.99], axis=0)
    copied = chroma[composed.covered]
    return float(((copied < lo - _FOREIGN_MARGIN) | (copied > hi + _FOREIGN_MARGIN)).any(axis=1).mean())


def _border_mismatch(image: np.ndarray, known: np.ndarray, composed: ShiftMap) -> tuple[np.ndarray, np.ndarray]:
    """Per known pixel beside a covered hole pixel: its value minus what that pixel's shift copies
    to its place, averaged over such neighbours; and how many there are."""
    h, w = known.shape
    total, count = np.zeros(image.shape, np.float32), np.zeros((h, w), np.float32)
    ys, xs = np.nonzero(composed.covered)
    t = composed.shifts[composed.labels[ys, xs]]
    for dy, dx in NEIGHBOURS4:
        qy, qx = ys + dy, xs + dx
        sy, sx = qy + t[:, 0], qx + t[:, 1]
        ok = ((qy >= 0) & (qy < h) & (qx >= 0) & (qx < w) & (sy >= 0) & (sy < h) & (sx >= 0) & (sx < w))
        ok[ok] &= known[qy[ok], qx[ok]] & known[sy[ok], sx[ok]]
        np.add.at(total, (qy[ok], qx[ok]), image[qy[ok], qx[ok]] - image[sy[ok], sx[ok]])
        np.add.at(count, (qy[ok], qx[ok]), 1.0)
    return total / np.maximum(count, 1)[..., None], count
