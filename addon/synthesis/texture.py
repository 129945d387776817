"""Fill a hole in an image by order-independent multi-resolution texture synthesis.

Wei and Levoy, "Order-independent texture synthesis" (2002), thesis chapter 2. Exemplar and output
have Gaussian pyramids; a pixel's neighbourhood is the n x n window on its own level plus a 3 x 3
window on the next coarser level, sampled bilinearly at the pixel's own position so that both
pyramids are compared in the same phase. Each level is computed in generations: generation g of
level l reads only coarser levels and generation g - 1 of level l (thesis eq. 2.1), so any pixel
can be computed on demand (`OrderIndependentSynthesis`); `fill` is the same computation done for
all hole pixels at once, level by level. Known pixels constrain every level and generation
(thesis 2.5). Pixels neither known nor hole ("don't care") are left out: they are never exemplar,
and their entries get weight 0 in every distance (masked sum of squared differences).

Beyond the thesis, three things make the fill hold up on floors: the accelerated search
compares each pixel only with k-coherence candidates, so structures are copied whole; whole-hole
copies along the shifts under which the hole's surroundings recur ("offsets") start each level,
carrying tile and plank lines across large holes; and a smooth correction removes shade steps at
the hole's border. All three read only coarser levels, earlier generations and known pixels.

Neighbourhood vectors are quantised to integers (bytes: the exemplar's vectors, read at random by
the search, take a quarter of the memory of floats) small enough that every squared distance,
also through float32 matrix products, is an exact integer. So no result depends on batch shape or
summation order, which makes on-demand requests bit-identical to `fill`, and randomness is a hash
of (seed, level, generation, y, x), never a sequential stream.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from ..errors import Cancelled, DimredError
from .correlation import correlation, correlation_size, cross_spectrum, spectrum

_BINOMIAL = (1 / 16, 4 / 16, 6 / 16, 4 / 16, 1 / 16)  # Python floats keep float32 arrays float32
_EXACT = 2**24 - 1  # float32 holds every integer up to this
_MAX_LEVELS = 8
_CHUNK = 1 << 22  # elements of the larger temporaries per chunk (16 MiB of float32)
# conjugate-gradient steps from the pull-push start: they settle the membrane near the border, where
# it matters; solving to convergence (hundreds of steps on a 256 px hole) changed the benchmark's
# mean error by less than 1e-4
_MEMBRANE_STEPS = 32
_OUTLIER = 3.0  # border mismatches further than this many robust deviations from the median are clipped
_STEPS4 = [(0, 1), (0, -1), (1, 0), (-1, 0)]
_WINDOW3 = [(dy, dx) for dy in (-1, 0, 1) for dx in (-1, 0, 1)]
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_OFFSET_POOL = 64  # shifts ranked on the coarsest level, before the finest level picks the best
MIN_WINDOWS = 16  # exemplar neighbourhoods a level needs at least


@dataclass(frozen=True)
class SynthesisParams:
    """What the synthesis trades: each knob buys quality with time.

    neighbourhood: odd side n of the window on a pixel's own level (a 3 x 3 window of the coarser
        level comes on top). Larger follows larger structures; time grows with n^2. 7, as in the
        add-on's presets, keeps tile and plank lines whole where 5 breaks them.
    levels: pyramid levels; 0 = as many as bring the hole down to about n pixels across on the
        coarsest level, so that every hole pixel there sees the surrounding texture (fewer where the
        exemplar would get too small). More levels keep larger structures, such as tile lines.
    generations: searches per level above the finest. The first one starts from the coarser level's
        choices; later ones settle the seams between the copied pieces. Time is linear in it.
    finest_generations: searches on the finest level, the most costly one. One suffices: its start,
        the settled coarser level's choices upsampled, is coherent already (a second one changed
        the benchmark's mean error by under 0.001 and took 40 % longer).
    search: 'exhaustive' is the exact nearest neighbour among all exemplar windows (the reference;
        minutes for large holes). 'accelerated' compares each pixel with k-coherence candidates
        only: the windows its 3 x 3 neighbours and its coarser-level parent's 3 x 3 neighbours
        copied from, shifted to its own position, the offsets below and random_candidates random
        ones. Being restricted to coherent copies, it keeps structures whole where the exact
        search, pixel by pixel, breaks them up; it is also far faster.
    random_candidates: accelerated: random exemplar windows tried per pixel and generation; they
        let a pixel leave a poor coherent patch, at a small cost each.
    max_exemplar: exemplar pixels used at most, those nearest the hole: bounds memory (about 500
        bytes per exemplar pixel) and time on large rasters. Smaller regions lose the copies along
        long periods (the offsets need the hole shifted by a period to lie in the exemplar).
    offsets: translations tried as whole-hole copies (0 = none: start from noise as in the thesis).
        They are the shifts under which the ring of known pixels around the hole best matches the
        exemplar (statistics of patch offsets, He and Sun 2012), found on the coarsest level and
        refined on each finer one; generation 0 copies along the best one that fits each pixel,
        and the accelerated search tries all of them. They carry periodic structure (tile and
        plank lines) into the middle of large holes, which a few generations cannot.
    smooth_seams: add to the fill a smooth field that takes the step between the copied texture
        and the known pixels along the hole's border to zero (the mismatch on the border ring,
        outliers clipped, interpolated as a membrane over the hole, as in Poisson blending):
        removes tint, brightness and texture steps where the exemplar pieces differ from the
        surroundings. False keeps pure exemplar values.
    """

    neighbourhood: int = 7
    levels: int = 0
    generations: int = 2
    finest_generations: int = 1
    search: str = "accelerated"
    random_candidates: int = 2
    max_exemplar: int = 1 << 18
    offsets: int = 8
    smooth_seams: bool = True


ProgressFn = Callable[[int, np.ndarray], None]
CancelFn = Callable[[], bool]


def fill(image: np.ndarray, known: np.ndarray, hole: np.ndarray, params: SynthesisParams = SynthesisParams(),
         **options: Any) -> np.ndarray:
    """`image` (H, W, C) with the `hole` pixels synthesised: `fill_with_sources`'s image."""
    return fill_with_sources(image, known, hole, params, **options)[0]


def fill_with_sources(
    image: np.ndarray,
    known: np.ndarray,
    hole: np.ndarray,
    params: SynthesisParams = SynthesisParams(),
    *,
    exemplar: np.ndarray | None = None,
    exemplar_valid: np.ndarray | None = None,
    seed: int = 0,
    progress: ProgressFn | None = None,
    cancel: CancelFn | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """`image` (H, W, C) with the `hole` pixels synthesised; every other pixel is returned
    unchanged. And (H, W, 2) the exemplar pixel (row, column) each hole pixel copies
    (`OrderIndependentSynthesis.sources`), -1 elsewhere.

    `known` pixels constrain the fill (a pixel in both masks counts as hole); pixels in neither
    mask are left out of all distances and never copied. The
    exemplar is `exemplar` (h, w, C) where `exemplar_valid` (default: all of it), or else the known
    pixels of `image`. `progress(level, preview)` is called after each level, coarsest first, with
    a full-size image whose hole shows that level upsampled; the last call shows the result.
    `cancel()` returning True raises `Cancelled` at the next step. Raises `DimredError` on bad input
    or an exemplar with too few complete neighbourhoods.
    """
    synth = OrderIndependentSynthesis(image, known, hole, params, exemplar=exemplar, exemplar_valid=exemplar_valid,
                                      seed=seed, cancel=cancel)
    if progress is not None:  # without it, level 0 computes of the coarser levels just what it reads
        for level in range(synth.levels - 1, 0, -1):
            progress(level, synth.preview(level))
    out = synth.preview(0)
    if progress is not None:
        progress(0, out)
    return out, synth.sources()


class OrderIndependentSynthesis:
    """The synthesis pyramid of one fill, computed lazily and memoised.

    `pixels(level, ys, xs)` computes just what the requested pixels depend on (coarser levels,
    earlier generations of their own level, recursively); requests in any order and batches give
    exactly the values `fill` gives. Arguments as for `fill`.
    """

    def __init__(
        self,
        image: np.ndarray,
        known: np.ndarray,
        hole: np.ndarray,
        params: SynthesisParams = SynthesisParams(),
        *,
        exemplar: np.ndarray | None = None,
        exemplar_valid: np.ndarray | None = None,
        seed: int = 0,
        cancel: CancelFn | None = None,
    ) -> None:
        image, known, hole = _check_inputs(image, known, hole, params)
        ex_image, ex_valid = _exemplar_source(image, known, hole, params.max_exemplar, exemplar, exemplar_valid)
        self._params, self._seed, self._cancel = params, seed, cancel
        self._image, self._hole0 = image, hole
        self._quantiser = _Quantiser.spanning(ex_image[ex_valid], params.neighbourhood, image.shape[2])
        levels = params.levels or _auto_levels(hole, params.neighbourhood)
        ex_pyr = pyramid(ex_image, ex_valid.astype(np.float32), levels)
        self._ex = _exemplar_levels(ex_pyr, params, self._quantiser)  # automatic levels may drop the coarsest
        self.levels = len(self._ex)

        known_pyr = pyramid(image, known.astype(np.float32), self.levels)
        hole_pyr = pyramid(None, hole.astype(np.float32), self.levels)
        self._hole = [w > 0 for _, w in hole_pyr]
        self._known = [(w > 0) & ~h for (_, w), h in zip(known_pyr, self._hole, strict=True)]
        self._care = [k | h for k, h in zip(self._known, self._hole, strict=True)]
        self._seams: list[np.ndarray | None] = [None] * self.levels
        self._gens = [params.finest_generations] + [params.generations] * (self.levels - 1)  # searches per level
        # per level and generation: the image (known pixels, and the hole as far as computed), the
        # exemplar window each hole pixel copies, and which are computed; generation 0 is the start
        # (`_start`), generations 1..g the searches
        self._img = [[np.where(k[..., None], v, 0).astype(np.float32) for _ in range(g + 1)]
                     for (v, _), k, g in zip(known_pyr, self._known, self._gens, strict=True)]
        levels_gens = list(zip(self._hole, self._gens, strict=True))
        self._src = [[np.full(h.shape, -1, np.int64) for _ in range(g + 1)] for h, g in levels_gens]
        self._done = [[np.zeros(h.shape, bool) for _ in range(g + 1)] for h, g in levels_gens]
        self._offsets = (_find_offsets(self._hole, self._known, known_pyr, ex_pyr, self._ex, params)
                         if params.offsets else None)

    def pixels(self, level: int, ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """Final values (M, C) of pixels (ys, xs) of `level`: synthesised in the hole (with the
        seam correction, which needs the hole's border on that level), the known value where
        known, NaN where neither."""
        ys, xs = np.asarray(ys, np.int64), np.asarray(xs, np.int64)
        want = np.zeros(self._hole[level].shape, bool)
        want[ys, xs] = True
        g = self._gens[level]
        self._ensure(level, g, want)
        values = self._img[level][g][ys, xs] + self._seam_field(level)[ys, xs]
        return np.where(self._care[level][ys, xs, None], values, np.nan)

    def level_image(self, level: int) -> np.ndarray:
        """`level` of the output pyramid (known pixels and the synthesised hole; 0 where neither)."""
        g = self._gens[level]
        self._ensure(level, g, self._hole[level])
        return self._img[level][g] + self._seam_field(level)

    def preview(self, level: int) -> np.ndarray:
        """The full-size image with its hole taken from `level`, upsampled (computes the level)."""
        values, weight = self.level_image(level), self._care[level].astype(np.float32)
        for l in range(level - 1, -1, -1):
            values, weight = _expand(values, weight, self._hole[l].shape)
        out = self._image.copy()
        out[self._hole0] = values[self._hole0]
        return out

    def sources(self) -> np.ndarray:
        """(H, W, 2) the exemplar pixel (row, column) at the centre of the window each hole pixel
        of the finest level copies, -1 elsewhere (computes the level). The seam correction comes
        on top of the copy."""
        g = self._gens[0]
        self._ensure(0, g, self._hole[0])
        src = self._src[0][g]
        return np.where((src >= 0)[..., None], self._ex[0].pos[np.maximum(src, 0)], -1)

    def _seam_field(self, l: int) -> np.ndarray:
        """What `smooth_seams` adds to level l (0 outside the hole): the mismatch between each known
        pixel next to the hole and the value the copy of its hole neighbour would have there,
        interpolated smoothly over the hole. Needs the hole's border pixels, and only them."""
        if self._seams[l] is None:
            field = np.zeros(self._img[l][0].shape, np.float32)
            border = self._hole[l] & _dilate(self._known[l], 1)
            if self._params.smooth_seams and border.any():
                self._ensure(l, self._gens[l], border)
                values, weight = _border_mismatch(self._ex[l], self._img[l][-1], self._src[l][-1], self._known[l],
                                                  border)
                fixed = weight > 0
                # the membrane takes each border value as it is: outliers (border pixels whose
                # reflectance is off where the irradiance estimate is poor, as in a contact shadow)
                # would be carried into the hole, so they are clipped first
                field = membrane(clip_outliers(values, fixed), fixed, self._hole[l])
            self._seams[l] = np.where(self._hole[l][..., None], field, 0).astype(np.float32)
        return self._seams[l]

    def _ensure(self, l: int, g: int, want: np.ndarray) -> None:
        """Compute the hole pixels of `want` on level l, generation g, after what they depend on."""
        need = want & self._hole[l] & ~self._done[l][g]
        if not need.any():
            return
        if l + 1 < self.levels:
            parents = _parents(need, self._hole[l + 1].shape)
            self._ensure(l + 1, self._gens[l + 1], parents if g == 0 else _dilate(parents, 2))
        if g > 0:
            self._ensure(l, g - 1, _dilate(need, max(self._params.neighbourhood // 2, 1)))
        if self._cancel is not None and self._cancel():
            raise Cancelled()
        ys, xs = np.nonzero(need)
        idx = self._start(l, ys, xs) if g == 0 else self._search(l, g, ys, xs)
        ex = self._ex[l]
        self._src[l][g][ys, xs] = idx
        self._img[l][g][ys, xs] = ex.values[ex.pos[idx, 0], ex.pos[idx, 1]]
        self._done[l][g][ys, xs] = True

    def _start(self, l: int, ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """Generation 0. Coarsest level: a copy along the best-ranked offset that fits the pixel,
        else noise drawn from the exemplar. Finer levels: the parent's offset, refined to this
        level, else the exemplar window the parent chose, upsampled; else noise."""
        idx = self._random(l, 0, ys, xs, 0)
        ex = self._ex[l]
        if l + 1 < self.levels:
            parent_src = self._src[l + 1][-1][ys // 2, xs // 2]
            parent = self._ex[l + 1].pos[parent_src]
            up = _lookup(ex.index, 2 * parent[:, 0] + ys % 2, 2 * parent[:, 1] + xs % 2)
            idx = np.where(up >= 0, up, idx)
        if self._offsets is None or not len(self._offsets[l]):
            # No shift qualified (the exemplar is too small to hold the hole shifted by one).
            return idx
        cand = self._offset_candidates(l, ys, xs)
        if l + 1 < self.levels:
            moved = parent - np.stack([ys // 2, xs // 2], axis=1)
            same = (moved[:, None, :] == self._offsets[l + 1][None]).all(axis=2)
            label = np.where(same.any(axis=1), same.argmax(axis=1), -1)
            pick = np.where(label >= 0, cand[np.arange(len(ys)), np.maximum(label, 0)], -1)
        else:
            fits = cand >= 0
            pick = np.where(fits.any(axis=1), cand[np.arange(len(ys)), fits.argmax(axis=1)], -1)
        return np.where(pick >= 0, pick, idx)

    def _offset_candidates(self, l: int, ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """(M, K) exemplar windows at the pixels moved by each offset of level l, -1 where none."""
        t = self._offsets[l]
        return _lookup(self._ex[l].index, ys[:, None] + t[None, :, 0], xs[:, None] + t[None, :, 1])

    def _search(self, l: int, g: int, ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """Generation g >= 1: the best exemplar window for each pixel's neighbourhood in generation g - 1."""
        coarse = None if l + 1 == self.levels else (self._img[l + 1][-1], self._care[l + 1])
        # only the pixels' windows are read: quantise and upsample just their bounding box
        box = _bounding_box(ys, xs, max(self._params.neighbourhood // 2, 2), self._hole[l].shape)
        planes = self._quantiser.planes(self._img[l][g - 1], self._care[l], coarse, box)
        q, ok = _gather(planes, ys - box[0], xs - box[2])
        w = ok.astype(np.float32)
        ex = self._ex[l]
        if self._params.search == "exhaustive":
            return _nearest(ex.vec, ex.sq, q, w)
        return _best_candidate(ex.vec, ex.sq, q, w, self._candidates(l, g, ys, xs))

    def _candidates(self, l: int, g: int, ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
        """(M, K) exemplar windows to try, -1 where none: k-coherence from generation g - 1 and from
        the coarser level (windows that continue what the neighbours copied), and random ones."""
        ex, src = self._ex[l], self._src[l][g - 1]
        cands = []
        for dy, dx in _WINDOW3:
            s = _lookup(src, ys + dy, xs + dx)
            p = ex.pos[np.maximum(s, 0)]
            cands.append(np.where(s >= 0, _lookup(ex.index, p[:, 0] - dy, p[:, 1] - dx), -1))
        if l + 1 < self.levels:
            coarse_src, coarse_pos = self._src[l + 1][-1], self._ex[l + 1].pos
            for dy, dx in _WINDOW3:
                cy, cx = ys // 2 + dy, xs // 2 + dx
                s = _lookup(coarse_src, cy, cx)
                p = coarse_pos[np.maximum(s, 0)]
                c = _lookup(ex.index, 2 * p[:, 0] + ys - 2 * cy, 2 * p[:, 1] + xs - 2 * cx)
                cands.append(np.where(s >= 0, c, -1))
        cands += [self._random(l, g, ys, xs, j) for j in range(self._params.random_candidates)]
        if self._offsets is not None:
            cands += list(self._offset_candidates(l, ys, xs).T)
        return np.stack(cands, axis=1)

    def _random(self, l: int, g: int, ys: np.ndarray, xs: np.ndarray, j: int) -> np.ndarray:
        """A random exemplar window per pixel, a function of (seed, level, generation, y, x, j) alone."""
        return (_hash(self._seed, ys, xs, l, g, j) % np.uint64(len(self._ex[l].pos))).astype(np.int64)


def _exemplar_source(image: np.ndarray, known: np.ndarray, hole: np.ndarray, max_exemplar: int,
                     exemplar: np.ndarray | None, exemplar_valid: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """The exemplar image and its valid pixels: `exemplar` where `exemplar_valid`, else the known
    pixels of `image`; either cut to the `max_exemplar` pixels nearest the hole (or the centre)."""
    if exemplar is None:
        if not known.any():
            raise DimredError("nothing is known around the hole: there is no exemplar to synthesise from")
        return image, known & _nearest_pixels(known, hole, max_exemplar)
    ex_image, ex_valid = _check_exemplar(exemplar, exemplar_valid, image.shape[2])
    centre = np.zeros(ex_valid.shape, bool)
    centre[ex_valid.shape[0] // 2, ex_valid.shape[1] // 2] = True
    return ex_image, ex_valid & _nearest_pixels(ex_valid, centre, max_exemplar)


@dataclass(frozen=True)
class _Quantiser:
    """Neighbourhood values as bytes: rint((v - lo) * scale) clipped to 0..qmax, with qmax small
    enough that every squared distance between two neighbourhoods is an exact float32 integer."""

    lo: float
    scale: float
    qmax: int
    neighbourhood: int

    @classmethod
    def spanning(cls, values: np.ndarray, neighbourhood: int, channels: int) -> _Quantiser:
        """The quantiser that maps the range of `values` (the valid exemplar's) onto 0..qmax."""
        lo, hi = float(values.min()), float(values.max())
        qmax = min(255, int(np.sqrt(_EXACT / ((neighbourhood * neighbourhood + 9) * channels))))
        return cls(lo, qmax / (hi - lo) if hi > lo else 1.0, qmax, neighbourhood)

    def planes(self, level: np.ndarray, ok: np.ndarray, coarse: tuple | None,
               box: tuple[int, int, int, int] | None = None) -> list[tuple]:
        """`_planes` with byte values, 0 where not ok."""
        return [(np.where(o[..., None], np.clip(np.rint((v - self.lo) * self.scale), 0, self.qmax), 0)
                 .astype(np.uint8), o, size, step)
                for v, o, size, step in _planes(level, ok, coarse, self.neighbourhood, box)]


def _exemplar_levels(ex_pyr: list, params: SynthesisParams, quantiser: _Quantiser) -> list[_ExemplarLevel]:
    """The exemplar's levels, finest first. Automatic levels (params.levels 0) drop the coarsest
    while it has fewer than MIN_WINDOWS complete windows; DimredError when a level still has."""
    levels = len(ex_pyr)
    while True:
        coarsest = _exemplar_level(ex_pyr, levels - 1, levels, quantiser)
        if len(coarsest.pos) >= MIN_WINDOWS or params.levels or levels == 1:
            break
        levels -= 1
    exemplars = [_exemplar_level(ex_pyr, l, levels, quantiser) for l in range(levels - 1)] + [coarsest]
    n = params.neighbourhood
    for l, ex in enumerate(exemplars):
        if len(ex.pos) < MIN_WINDOWS:
            raise DimredError(
                f"the exemplar has only {len(ex.pos)} complete {n}x{n} neighbourhoods on pyramid level {l} "
                f"(at least {MIN_WINDOWS} needed): give a larger exemplar region, fewer levels or a smaller "
                "neighbourhood"
            )
    return exemplars


def _exemplar_level(pyr: list, l: int, levels: int, quantiser: _Quantiser) -> _ExemplarLevel:
    """Quantised neighbourhoods of all exemplar windows complete on level l (and the coarser one)."""
    values, weight = pyr[l]
    valid = weight >= 1 - 1e-6  # the whole blur footprint was exemplar
    coarse = (pyr[l + 1][0], pyr[l + 1][1] >= 1 - 1e-6) if l + 1 < levels else None
    planes = quantiser.planes(values, valid, coarse)
    pos = np.stack(np.nonzero(_complete(planes)), axis=1)
    d = sum(size * size for _, _, size, _ in planes) * values.shape[2]
    vec = np.empty((len(pos), d), np.uint8)
    views = _value_windows(planes)
    rows = max(1, _CHUNK // d)
    for s in range(0, len(pos), rows):
        vec[s:s + rows] = _take_windows(views, pos[s:s + rows, 0], pos[s:s + rows, 1])
    index = np.full(valid.shape, -1, np.int64)
    index[pos[:, 0], pos[:, 1]] = np.arange(len(pos))
    return _ExemplarLevel(values.astype(np.float32), valid, pos, index, vec,
                          np.einsum("nd,nd->n", vec, vec, dtype=np.float32))


def _border_mismatch(ex: _ExemplarLevel, img: np.ndarray, src: np.ndarray, known: np.ndarray,
                     border: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per known pixel next to the hole: its value in `img` minus what the copies (`src`) of its
    hole neighbours on the `border` hold at its place (averaged over them), and which pixels have one."""
    total, count = np.zeros(img.shape, np.float32), np.zeros(img.shape[:2], np.float32)
    ys, xs = np.nonzero(border)
    origin = ex.pos[src[ys, xs]]
    for dy, dx in _STEPS4:
        copy, ok = _sample(ex.values, ex.valid, origin[:, 0] + dy, origin[:, 1] + dx)
        qy, qx = ys + dy, xs + dx
        ok &= _lookup(known.astype(np.int8), qy, qx) > 0
        total[qy[ok], qx[ok]] += img[qy[ok], qx[ok]] - copy[ok]  # one hole neighbour per direction
        count[qy[ok], qx[ok]] += 1
    return total / np.maximum(count, 1)[..., None], (count > 0).astype(np.float32)


def _find_offsets(holes: list[np.ndarray], known: list[np.ndarray], known_pyr: list, ex_pyr: list,
                  exemplars: list[_ExemplarLevel], params: SynthesisParams) -> list[np.ndarray]:
    """Per level, the (K, 2) offsets t under which the known ring around the hole best matches
    the exemplar at ring + t. A pool of shifts is ranked on the coarsest level over all shifts
    (by FFT), refined by -1..1 and halved on every finer level, and cut to the K best on the
    finest level, where the ring shows the most detail. Row k is one offset on all levels."""
    levels = len(holes)
    top = levels - 1
    rings = [_dilate(h, params.neighbourhood // 2 + 1) & k for h, k in zip(holes, known, strict=True)]
    valid = [w >= 1 - 1e-6 for _, w in ex_pyr]
    offsets = [None] * levels
    offsets[top] = _rank_offsets(known_pyr[top][0], rings[top], holes[top], ex_pyr[top][0], valid[top],
                                 exemplars[top].index >= 0, _OFFSET_POOL)
    keep = np.arange(len(offsets[top]))
    for l in range(top - 1, -1, -1):
        # halve the pool on each level, the finer levels judging the fewer, better shifts
        t, score = _refine_offsets(2 * offsets[l + 1][keep], known_pyr[l][0], rings[l], ex_pyr[l][0], valid[l])
        offsets[l] = np.zeros_like(offsets[top])
        offsets[l][keep] = t
        keep = keep[np.argsort(score, kind="stable")[:max(params.offsets, len(keep) // 2)]]
    return [t[keep[:params.offsets]] for t in offsets]


@dataclass
class _ExemplarLevel:
    values: np.ndarray  # (h, w, C) the exemplar's pyramid level
    valid: np.ndarray  # (h, w) pixels whose whole blur footprint was exemplar
    pos: np.ndarray  # (N, 2) centres of complete windows
    index: np.ndarray  # (h, w) row of each centre in pos and vec, -1 elsewhere
    vec: np.ndarray  # (N, D) quantised neighbourhoods (uint8)
    sq: np.ndarray  # (N,) their squared norms


def pyramid(values: np.ndarray | None, weight: np.ndarray, levels: int) -> list[tuple[np.ndarray | None, np.ndarray]]:
    """Gaussian pyramid by normalised convolution: [(values, weight)] per level, finest first.

    Each level blurs the one below with the 5-tap binomial filter and keeps the even rows and
    columns; only pixels with weight contribute to values. A level's weight is the weighted share
    of its blur footprint that had weight (1 = all of it; pixels outside the image count as 0).
    `values` (H, W, C) may be None to build the weights alone.
    """
    if values is not None:
        values = np.where(weight[..., None] > 0, values, 0).astype(np.float32)
    out = [(values, weight)]
    for _ in range(levels - 1):
        den = _blur_decimate(weight)
        if values is not None:
            num = _blur_decimate(values * weight[..., None])
            values = np.where(den[..., None] > 0, num / np.where(den > 0, den, 1)[..., None], 0)
        weight = den
        out.append((values, weight))
    return out


def neighbourhoods(
    level: np.ndarray,
    level_ok: np.ndarray,
    coarse: tuple[np.ndarray, np.ndarray] | None,
    ys: np.ndarray,
    xs: np.ndarray,
    size: int,
) -> tuple[np.ndarray, np.ndarray]:
    """Neighbourhood vectors (M, D) of pixels (ys, xs) and which entries are valid (M, D).

    The entries are the size x size window of `level` (H, W, C) around the pixel, channel by
    channel and row by row, then, if `coarse` = (values (h, w, C), ok (h, w)) is given, the coarser
    level sampled bilinearly at (y / 2 + dy, x / 2 + dx) for dy, dx in -1..1, in the same order.
    Entries outside the image or touching a pixel that is not ok are invalid and 0.
    """
    return _gather(_planes(level, level_ok, coarse, size), ys, xs)


def _planes(level: np.ndarray, ok: np.ndarray, coarse: tuple | None, size: int,
            box: tuple[int, int, int, int] | None = None) -> list[tuple]:
    """What a neighbourhood samples: [(image, ok, window size, step)] on the level's grid; the
    coarser level is upsampled onto it, so its 3 x 3 window is taken with step 2. `box` =
    (y0, y1, x0, x1) crops all planes to rows y0..y1 - 1 and columns x0..x1 - 1 of the level."""
    y0, y1, x0, x1 = box or (0, ok.shape[0], 0, ok.shape[1])
    planes = [(level[y0:y1, x0:x1], ok[y0:y1, x0:x1], size, 1)]
    if coarse is not None:
        planes.append((*_upsample(*coarse, np.arange(y0, y1), np.arange(x0, x1)), 3, 2))
    return planes


def _bounding_box(ys: np.ndarray, xs: np.ndarray, margin: int, shape: tuple[int, int]) -> tuple[int, int, int, int]:
    """(y0, y1, x0, x1): the pixels' bounding box grown by `margin`, within an image of `shape`."""
    return (max(int(ys.min()) - margin, 0), min(int(ys.max()) + margin + 1, shape[0]),
            max(int(xs.min()) - margin, 0), min(int(xs.max()) + margin + 1, shape[1]))


def _gather(planes: list[tuple], ys: np.ndarray, xs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The windows of all planes around (ys, xs), concatenated: values (M, D), 0 where invalid, and validity."""
    return _gather_values(planes, ys, xs), np.concatenate(
        [np.repeat(_windows(np.pad(ok, size // 2 * step), size, step)[ys, xs].reshape(len(ys), 1, -1),
                   img.shape[2], axis=1).reshape(len(ys), -1) for img, ok, size, step in planes], axis=1)


def _gather_values(planes: list[tuple], ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """Window values (M, D) of all planes around (ys, xs), channel by channel, 0 where not ok."""
    return _take_windows(_value_windows(planes), ys, xs)


def _value_windows(planes: list[tuple]) -> list[np.ndarray]:
    """Per plane, the view (H, W, C, size, size) of its windows, 0 where not ok (padded once, read many times)."""
    views = []
    for img, ok, size, step in planes:
        r = size // 2 * step
        views.append(_windows(np.pad(np.where(ok[..., None], img, 0), ((r, r), (r, r), (0, 0))), size, step))
    return views


def _take_windows(views: list[np.ndarray], ys: np.ndarray, xs: np.ndarray) -> np.ndarray:
    """The windows of all views at (ys, xs), concatenated: (M, D)."""
    return np.concatenate([v[ys, xs].reshape(len(ys), -1) for v in views], axis=1)


def _windows(padded: np.ndarray, size: int, step: int) -> np.ndarray:
    """View (H, W, [C,] size, size) of the size x size windows with `step` of an image padded by size // 2 * step."""
    span = size // 2 * step * 2 + 1
    return sliding_window_view(padded, (span, span), axis=(0, 1))[..., ::step, ::step]


def _complete(planes: list[tuple]) -> np.ndarray:
    """Pixels whose windows are valid in every plane."""
    out = np.ones(planes[0][1].shape, bool)
    for _, ok, size, step in planes:
        out &= _windows(np.pad(ok, size // 2 * step), size, step).all(axis=(2, 3))
    return out


def _upsample(coarse: np.ndarray, ok: np.ndarray, y: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The coarser level on the finer grid's rows y and columns x: coarse pixel i sits at fine 2i,
    so odd positions average two neighbours; valid where all contributing pixels are inside and ok."""
    h, w = ok.shape
    y0, y1, x0, x1 = y // 2, (y + 1) // 2, x // 2, (x + 1) // 2
    inside = (y1 < h)[:, None] & (x1 < w)[None, :]
    y1, x1 = np.minimum(y1, h - 1), np.minimum(x1, w - 1)
    rows0, rows1 = coarse[y0], coarse[y1]
    # pairwise halves: even positions reproduce the coarse pixel exactly
    up = ((rows0[:, x0] + rows0[:, x1]) * 0.5 + (rows1[:, x0] + rows1[:, x1]) * 0.5) * 0.5
    valid = inside & ok[y0][:, x0] & ok[y0][:, x1] & ok[y1][:, x0] & ok[y1][:, x1]
    return up, valid


def _sample(img: np.ndarray, ok: np.ndarray, y: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """img[y, x] and whether it is inside and ok (0 where not)."""
    h, w = ok.shape
    inside = (y >= 0) & (y < h) & (x >= 0) & (x < w)
    yc, xc = np.clip(y, 0, h - 1), np.clip(x, 0, w - 1)
    valid = inside & ok[yc, xc]
    return np.where(valid[..., None], img[yc, xc], 0), valid


def _nearest(ex: np.ndarray, sq: np.ndarray, q: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Index of the exemplar row nearest each query row in masked squared distance, exactly.

    sum w (q - e)^2 = sum w q^2 - 2 q.e + sum w e^2 (q is 0 where w is); the first term is the
    same for every e, so it is left out. All terms are exact integers in float32."""
    out = np.empty(len(q), np.int64)
    rows = max(1, 4 * _CHUNK // max(len(ex), 1))  # tall products: packing the exemplar costs per call
    ex = ex.astype(np.float32)  # matrix products run on floats
    ex_t = np.ascontiguousarray(ex.T)
    sq_t = None
    for s in range(0, len(q), rows):
        qs, ws = q[s:s + rows].astype(np.float32), w[s:s + rows]
        if ws.all():
            d = sq[None, :] - 2 * (qs @ ex_t)
        else:
            if sq_t is None:
                sq_t = np.ascontiguousarray((ex * ex).T)
            d = ws @ sq_t - 2 * (qs @ ex_t)
        out[s:s + rows] = d.argmin(axis=1)
    return out


def _best_candidate(ex: np.ndarray, sq: np.ndarray, q: np.ndarray, w: np.ndarray, cand: np.ndarray) -> np.ndarray:
    """The candidate (row of `cand`, -1 = none) nearest each query in masked squared distance
    (as in `_nearest`); ties go to the first candidate.

    Coherent candidate sets repeat themselves (neighbours that copied from one patch propose the
    same window), so each distinct candidate of a row is compared once: about a third of them."""
    out = np.empty(len(q), np.int64)
    rows = max(1, _CHUNK // (cand.shape[1] * ex.shape[1]))
    for s in range(0, len(q), rows):
        c, qs, ws = cand[s:s + rows], q[s:s + rows], w[s:s + rows]
        d = np.full(c.shape, np.inf, np.float32)
        full = ws.all(axis=1)
        r, k = np.nonzero(_first_occurrences(c) & full[:, None])
        d[r, k] = sq[c[r, k]] - 2 * np.einsum("pd,pd->p", ex[c[r, k]], qs[r], dtype=np.float32)
        if not full.all():
            em, qs = ex[np.maximum(c[~full], 0)].astype(np.float32), qs.astype(np.float32)
            dm = np.einsum("mkd,md->mk", em * em, ws[~full]) - 2 * np.einsum("mkd,md->mk", em, qs[~full])
            d[~full] = np.where(c[~full] >= 0, dm, np.inf)
        out[s:s + rows] = c[np.arange(len(c)), d.argmin(axis=1)]
    return out


def _first_occurrences(cand: np.ndarray) -> np.ndarray:
    """(M, K) True where cand is a window (>= 0) not already listed to its left in its row."""
    order = np.argsort(cand, axis=1, kind="stable")  # equal entries keep their left-to-right order
    ordered = np.take_along_axis(cand, order, axis=1)
    first = np.ones(cand.shape, bool)
    np.put_along_axis(first, order[:, 1:], ordered[:, 1:] != ordered[:, :-1], axis=1)
    return first & (cand >= 0)


def _rank_offsets(image: np.ndarray, ring: np.ndarray, hole: np.ndarray, ex: np.ndarray, ex_valid: np.ndarray,
                  centres: np.ndarray, count: int) -> np.ndarray:
    """The `count` shifts t (K, 2), best first, with the least mean squared difference between
    image[ring] and ex[ring + t], by FFT correlation over all shifts. A shift qualifies where half
    of the ring lands on valid exemplar and a quarter as much of the hole lands on window centres
    as under the best-covering shift; picked shifts suppress their 3 x 3 neighbours."""
    (h, w), (eh, ew) = ring.shape, ex_valid.shape
    size = correlation_size((h, w), (eh, ew))
    img = np.where(ring[..., None], image, 0).astype(np.float64)
    exv = np.where(ex_valid[..., None], ex, 0).astype(np.float64)
    f_ring, f_valid = spectrum(ring.astype(np.float64), size), spectrum(ex_valid.astype(np.float64), size)
    # the ring's sum of image^2 + ex^2 - 2 image.ex under each shift, transformed back once
    num = correlation(cross_spectrum(spectrum((img ** 2).sum(axis=2), size), f_valid)
                      + cross_spectrum(f_ring, spectrum((exv ** 2).sum(axis=2), size))
                      - 2 * cross_spectrum(spectrum(img, size), spectrum(exv, size)), size)
    cnt = np.rint(correlation(cross_spectrum(f_ring, f_valid), size))
    cover = np.rint(correlation(cross_spectrum(spectrum(hole.astype(np.float64), size),
                                               spectrum(centres.astype(np.float64), size)), size))
    ty, tx = np.arange(-(h - 1), eh), np.arange(-(w - 1), ew)
    grid = np.ix_(ty % size[0], tx % size[1])
    num, cnt, cover = num[grid], cnt[grid], cover[grid]
    ok = (cnt >= 0.5 * ring.sum()) & (cover > 0) & (cover >= 0.25 * cover.max())
    score = np.where(ok, np.maximum(num, 0) / np.maximum(cnt, 1), np.inf)
    picked = []
    for _ in range(count):
        best = int(np.argmin(score))
        if not np.isfinite(score.flat[best]):
            break
        by, bx = np.unravel_index(best, score.shape)
        picked.append((ty[by], tx[bx]))
        score[max(by - 1, 0):by + 2, max(bx - 1, 0):bx + 2] = np.inf
    return np.array(picked, np.int64).reshape(-1, 2)


def _refine_offsets(offsets: np.ndarray, image: np.ndarray, ring: np.ndarray, ex: np.ndarray,
                    ex_valid: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Each offset moved by the -1..1 step that best matches the ring to the exemplar on this
    level, and its mean squared difference there."""
    ry, rx = np.nonzero(ring)
    steps = np.array(_WINDOW3)
    trial = offsets[:, None, :] + steps[None]  # (K, 9, 2)
    v, ok = _sample(ex, ex_valid, ry + trial[..., :1], rx + trial[..., 1:])  # (K, 9, R, C)
    err = (np.square(v - image[ry, rx]).sum(axis=3) * ok).sum(axis=2)
    cnt = ok.sum(axis=2)
    score = np.where(cnt >= 0.5 * len(ry), err / np.maximum(cnt, 1), np.inf)
    step = score.argmin(axis=1)
    return offsets + steps[step], score[np.arange(len(offsets)), step]


def membrane(values: np.ndarray, fixed: np.ndarray, region: np.ndarray) -> np.ndarray:
    """`values` (H, W, C) interpolated over `region` from the pixels `fixed` around it: the
    membrane (discrete Laplace equation over 4-neighbours) that takes the fixed values at the
    region's border; neighbours neither fixed nor in the region carry no flux. Unlike a pull-push
    average it follows the border value by value, so the fill meets each known pixel. Relaxed
    from the pull-push estimate by _MEMBRANE_STEPS conjugate-gradient steps; 0 outside the region."""
    out = np.zeros(values.shape, np.float32)
    if not region.any():
        return out
    y0, y1, x0, x1 = _bounding_box(*np.nonzero(region), 1, region.shape)
    inside = region[y0:y1, x0:x1]
    known = fixed[y0:y1, x0:x1] & ~inside
    mask = inside[..., None].astype(np.float32)
    # neighbours that count: unknowns (coupled) and fixed pixels (their values go into b)
    degree = sum((_neighbour(inside, d) | _neighbour(known, d)).astype(np.float32) for d in _STEPS4)[..., None] * mask
    v = np.where(known[..., None], values[y0:y1, x0:x1], 0).astype(np.float32)
    b = sum(_neighbour(v, d) for d in _STEPS4) * mask

    def laplacian(x: np.ndarray) -> np.ndarray:  # on the unknowns; x is 0 elsewhere, so its neighbours there add 0
        xp = np.pad(x, ((1, 1), (1, 1), (0, 0)))
        h, w = x.shape[:2]
        return (degree * x - sum(xp[1 + dy:1 + dy + h, 1 + dx:1 + dx + w] for dy, dx in _STEPS4)) * mask

    x = np.where(inside[..., None], _pull_push(values, fixed.astype(np.float32))[y0:y1, x0:x1], 0).astype(np.float32)
    r = b - laplacian(x)
    p, rr = r.copy(), np.einsum("yxc,yxc->c", r, r)
    for _ in range(_MEMBRANE_STEPS):
        if not rr.any():  # solved exactly (e.g. a constant border)
            break
        ap = laplacian(p)
        alpha = rr / np.maximum(np.einsum("yxc,yxc->c", p, ap), 1e-30)
        x += alpha * p
        r -= alpha * ap
        rr, rr_old = np.einsum("yxc,yxc->c", r, r), rr
        p = r + rr / np.maximum(rr_old, 1e-30) * p
    out[y0:y1, x0:x1] = x
    return out


def _neighbour(a: np.ndarray, d: tuple[int, int]) -> np.ndarray:
    """out[y, x] = a[y + dy, x + dx] for a step d = (dy, dx) of at most 1 (0 / False beyond the edge)."""
    pad = np.pad(a, [(1, 1), (1, 1)] + [(0, 0)] * (a.ndim - 2))
    h, w = a.shape[:2]
    return pad[1 + d[0]:1 + d[0] + h, 1 + d[1]:1 + d[1] + w]


def clip_outliers(values: np.ndarray, fixed: np.ndarray) -> np.ndarray:
    """`values` clipped, channel by channel, to the median of the `fixed` ones +- _OUTLIER robust
    standard deviations (1.4826 x the median absolute deviation)."""
    if not fixed.any():
        return values
    median = np.median(values[fixed], axis=0)
    spread = _OUTLIER * 1.4826 * np.median(np.abs(values[fixed] - median), axis=0)
    return np.clip(values, median - spread, median + spread)


def _pull_push(values: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """Smooth interpolation of `values` known where weight > 0 (Gortler et al. 1996): pull the
    weighted values up a pyramid to 1 pixel, then push down, each level keeping its own values
    in proportion to their weight and taking the rest from the coarser level."""
    pyr = pyramid(values, weight, int(np.ceil(np.log2(max(weight.shape)))) + 1)
    estimate = pyr[-1][0]
    for v, w in reversed(pyr[:-1]):
        up, _ = _expand(estimate, np.ones(estimate.shape[:2], np.float32), w.shape)
        estimate = w[..., None] * v + (1 - w[..., None]) * up
    return estimate


def _blur_decimate(a: np.ndarray) -> np.ndarray:
    """Binomial 5-tap blur over the first two axes (zeros outside), keeping even rows and columns."""
    for axis in (0, 1):
        a = np.moveaxis(a, axis, 0)
        n = len(a)
        p = np.pad(a, [(2, 2)] + [(0, 0)] * (a.ndim - 1))
        a = sum(w * p[k:k + n:2] for k, w in enumerate(_BINOMIAL))
        a = np.moveaxis(a, 0, axis)
    return a


def _expand(values: np.ndarray, weight: np.ndarray, shape: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Bilinear upsampling by 2 to `shape`, normalised by weight (pixels of weight 0 do not bleed)."""
    num, den = values * weight[..., None], weight
    for axis, n in enumerate(shape):
        i = np.arange(n)
        i0, i1 = i // 2, np.minimum((i + 1) // 2, num.shape[axis] - 1)
        num = (np.take(num, i0, axis) + np.take(num, i1, axis)) * 0.5
        den = (np.take(den, i0, axis) + np.take(den, i1, axis)) * 0.5
    return np.where(den[..., None] > 0, num / np.where(den > 0, den, 1)[..., None], 0), den


def _box_count(mask: np.ndarray, r: int) -> np.ndarray:
    """Number of set pixels in the (2r+1)^2 window around each pixel (outside the image: unset)."""
    k = 2 * r + 1
    c = np.pad(np.pad(mask, r).astype(np.int32).cumsum(0).cumsum(1), ((1, 0), (1, 0)))
    return c[k:, k:] - c[:-k, k:] - c[k:, :-k] + c[:-k, :-k]


def _dilate(mask: np.ndarray, r: int) -> np.ndarray:
    return _box_count(mask, r) > 0


def _erode(mask: np.ndarray, r: int) -> np.ndarray:
    return _box_count(mask, r) == (2 * r + 1) ** 2


def _parents(mask: np.ndarray, shape: tuple[int, int]) -> np.ndarray:
    ys, xs = np.nonzero(mask)
    out = np.zeros(shape, bool)
    out[ys // 2, xs // 2] = True
    return out


def _lookup(table: np.ndarray, y: np.ndarray, x: np.ndarray) -> np.ndarray:
    """table[y, x], -1 outside the table."""
    h, w = table.shape
    inside = (y >= 0) & (y < h) & (x >= 0) & (x < w)
    return np.where(inside, table[np.clip(y, 0, h - 1), np.clip(x, 0, w - 1)], -1)


def _mix(h: np.ndarray) -> np.ndarray:
    """splitmix64's finaliser (uint64 arithmetic wraps, as intended)."""
    h = (h ^ (h >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
    h = (h ^ (h >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
    return h ^ (h >> np.uint64(31))


def _hash(seed: int, ys: np.ndarray, xs: np.ndarray, *keys: int) -> np.ndarray:
    """A 64-bit hash per pixel of (seed, keys, y, x): randomness that does not depend on what else
    is computed, or in which order."""
    h = np.full(ys.shape, seed % 2**64, np.uint64)
    for k in (*keys, ys, xs):
        h = _mix(h ^ (np.asarray(k, np.int64).astype(np.uint64) + _GOLDEN))
    return h


def _auto_levels(hole: np.ndarray, n: int) -> int:
    """Levels that bring the hole down to at most about n pixels across on the coarsest level."""
    levels, h = 1, hole
    while levels < _MAX_LEVELS and _erode(h, n // 2 + 1).any() and min(h.shape) >= 4 * n:
        h = _blur_decimate(h.astype(np.float32)) > 0
        levels += 1
    return levels


def _nearest_pixels(valid: np.ndarray, target: np.ndarray, count: int) -> np.ndarray:
    """The `count` or so valid pixels nearest (Chebyshev) to the bounding box of `target`."""
    if valid.sum() <= count:
        return np.ones(valid.shape, bool)
    target = target if target.any() else valid
    ty, tx = np.nonzero(target)
    y, x = np.arange(valid.shape[0])[:, None], np.arange(valid.shape[1])[None, :]
    dist = np.maximum(np.maximum(ty.min() - y, y - ty.max()).clip(0), np.maximum(tx.min() - x, x - tx.max()).clip(0))
    return dist <= np.partition(dist[valid], count - 1)[count - 1]


def _check_inputs(image, known, hole, params: SynthesisParams):
    image = np.asarray(image, np.float32)
    known, hole = np.asarray(known, bool), np.asarray(hole, bool)
    if image.ndim != 3 or known.shape != image.shape[:2] or hole.shape != image.shape[:2]:
        raise DimredError(f"synthesis wants an (H, W, C) image and (H, W) masks, got {image.shape}, "
                          f"{known.shape}, {hole.shape}")
    n = params.neighbourhood
    passes = min(params.generations, params.finest_generations, params.random_candidates)
    if (n < 1 or n % 2 == 0 or passes < 1 or params.levels < 0 or params.offsets < 0
            or params.max_exemplar < MIN_WINDOWS):
        raise DimredError(f"bad synthesis parameters {params}: the neighbourhood must be odd, generations and "
                          f"random candidates at least 1, levels and offsets not negative, max_exemplar at least "
                          f"{MIN_WINDOWS}")
    if params.search not in ("accelerated", "exhaustive"):
        raise DimredError(f"unknown synthesis search {params.search!r}: use 'accelerated' or 'exhaustive'")
    known = known & ~hole
    if not np.isfinite(image[known]).all():
        raise DimredError("the known pixels of the image to fill must be finite")
    return image, known, hole


def _check_exemplar(exemplar, valid, channels: int):
    exemplar = np.asarray(exemplar, np.float32)
    valid = np.ones(exemplar.shape[:2], bool) if valid is None else np.asarray(valid, bool)
    if exemplar.ndim != 3 or exemplar.shape[2] != channels or valid.shape != exemplar.shape[:2]:
        raise DimredError(f"the exemplar must be (h, w, {channels}) with an (h, w) mask, got {exemplar.shape} "
                          f"and {valid.shape}")
    if not valid.any():
        raise DimredError("the exemplar region is empty")
    if not np.isfinite(exemplar[valid]).all():
        raise DimredError("the exemplar must be finite")
    return exemplar, valid
