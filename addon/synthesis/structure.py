"""Structure first: a hole on a tiled or planked plane composed from shifted copies of the
visible floor, so that its lines run on in phase, with the seam at the hole's border blended.

The labels of a shift map (`shift_map`) are a tiling's repeats (`translations`), or, on planks
that repeat along no second direction, those translations and shifts along the floor's axes.
The step left between the copies and the known pixels along the border is taken to zero by a
membrane over the hole (the gradient-domain blend of Poisson image editing, whose guidance
field is the copies' own gradients), which also keeps the fill's mean on its surroundings where
the copies came from darker or lighter tiles. A stochastic
texture (carpet, concrete) has no dominant translation and matches itself along no axis:
`structure_fill` returns None and the order-independent synthesis fills it alone.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .shift_map import NEIGHBOURS4, ShiftMap, candidate_shifts, lattice_shifts, shift_map
from .texture import CancelFn, ProgressFn, SynthesisParams, clip_outliers, fill, membrane
from .translations import DOMINANT, Translations, dominant_translations, relative_difference

_TRANSLATIONS = 8  # of the texture's repeats, the best this many are labels (time grows with labels^2)
_ACROSS_PLANKS = 0.01  # the blend's conductance across planks, relative to along them


@dataclass(frozen=True)
class StructureFill:
    """`image` with the covered hole pixels composed and blended; `correction` (H, W, C) is the
    smooth field the blend added there (0 elsewhere), `shifts` the shift map behind it."""

    image: np.ndarray
    correction: np.ndarray
    shifts: ShiftMap
    translations: Translations

    @property
    def covered(self) -> np.ndarray:
        return self.shifts.covered


def structure_fill(image: np.ndarray, known: np.ndarray, hole: np.ndarray, *, footprint: np.ndarray | None = None,
                   seed: int = 0) -> StructureFill | None:
    """The `hole` of `image` (H, W, C) composed from shifted copies of its `known` pixels, or
    None where the texture has no dominant translation or no copy reaches the hole. `seed`
    varies the labels (the axis shifts' lengths, or which repeats of a tiling): another seed
    gives another, equally continuous fill."""
    image = np.asarray(image, np.float32)
    known = np.asarray(known, bool) & ~hole
    if known.sum() < hole.sum():  # too little floor seen to tell a repeat from a coincidence
        return None
    translations = dominant_translations(image, known, hole)
    along = None
    if translations.tiling:
        # combinations of a shift that is no repeat are none either (bench_synthesis's planks, a
        # tiling whose list held such a shift: 0.49 -> 0.66 in structure on the 64 px hole)
        repeats = translations.shifts[translations.contrast <= DOMINANT]
        shifts = lattice_shifts(repeats[:_TRANSLATIONS], image, known, hole, seed=seed)
    else:
        shifts = candidate_shifts(translations.shifts[:_TRANSLATIONS], hole, seed=seed)
        # planks of random shades repeat nothing as a whole, but match themselves along their length
        score = relative_difference(image, known, hole, shifts)
        if not (score <= DOMINANT).any():
            return None
        along = _plank_axis(shifts, score)
    composed = shift_map(image, known, hole, shifts, footprint=footprint)
    if not composed.covered.any():
        return None
    values, weight = _border_mismatch(image, known, composed)
    fixed = weight > 0
    correction = np.zeros_like(image)
    if fixed.any():
        values = clip_outliers(values, fixed)
        correction = membrane(values, fixed, composed.covered, conductance=_conductance(along))
    return StructureFill(image=np.where(composed.covered[..., None], composed.image + correction, image),
                         correction=correction, shifts=composed, translations=translations)


def fill_structured(image: np.ndarray, known: np.ndarray, hole: np.ndarray, params: SynthesisParams, *,
                    structure: bool = True, footprint: np.ndarray | None = None, seed: int = 0,
                    progress: ProgressFn | None = None, cancel: CancelFn | None = None
                    ) -> tuple[np.ndarray, StructureFill | None]:
    """`image` with its `hole` filled: composed from shifted copies where the texture repeats
    (with `structure`), the rest by the order-independent synthesis (`texture.fill`, which
    raises `DimredError` on too little exemplar). `progress(level, preview)` gets the composed
    image first (level -1) where the synthesis has more to do, then the synthesis's levels."""
    # Composed whatever the period of the repeats. Checkers of 17 cells (rotated_world at
    # 256x128) and 24 cells (far_dark_box at 1024x512) came out 0.98 and 0.79 in structure,
    # against 0.95 and 0.67 per pixel. Planks whose wood grain matches itself every 7 cells along
    # them (stool, warm_cylinder at 1024x512) were once left to the synthesis; since the copies
    # are read from the panorama itself they score 0.44 and 0.60 composed, against 0.16 and 0.55
    # per pixel, with less object and shadow error (0.131 and 0.212, against 0.142 and 0.225).
    got = structure_fill(image, known, hole, footprint=footprint, seed=seed) if structure else None
    if got is None:
        return fill(image, known, hole, params, seed=seed, progress=progress, cancel=cancel), None
    rest = hole & ~got.covered
    if not rest.any():
        return got.image, got
    if progress is not None:
        progress(-1, got.image)
    return fill(got.image, known | (hole & ~rest), rest, params, seed=seed, progress=progress, cancel=cancel), got


def _plank_axis(shifts: np.ndarray, score: np.ndarray) -> int | None:
    """The raster axis (0: rows, 1: columns) along which the shifts match the texture best: the
    planks' length; None where the shifts do not lie along both axes."""
    along_rows = (shifts[:, 1] == 0) & (shifts[:, 0] != 0)
    along_cols = (shifts[:, 0] == 0) & (shifts[:, 1] != 0)
    if not along_rows.any() or not along_cols.any():
        return None
    return 1 if score[along_cols].min() < score[along_rows].min() else 0


def _conductance(along: int | None) -> tuple[float, float]:
    """The blend's conductance between rows and between columns: on planks running along
    `along`, little across them. Each plank has its own shade and a copy from elsewhere brings
    another: the step where a plank enters the hole says how far off that plank's copy is, and
    an isotropic membrane spread it over the planks beside it as well (stool 0.44 -> 0.52 in
    structure at 1024x512, demo and warm_cylinder +0.00-0.01). Some conductance is left: the
    step at one border pixel is noisy (render noise, a joint), and interpolating each line on
    its own, exactly along the planks, did worse (demo 0.51, warm_cylinder 0.57)."""
    if along is None:
        return 1.0, 1.0
    return (1.0, _ACROSS_PLANKS) if along == 0 else (_ACROSS_PLANKS, 1.0)


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
