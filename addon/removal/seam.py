"""The filled pixels joined to the photograph around them without a step.

The fill is lit by the irradiance after the removal and the pixels around it by the ratio form,
two estimates that agree on average but not exactly: a proxy a few centimetres off, a lamp's
falloff, the synthesis's mean a few percent away, and the fill's edge shows as a step. It is
taken out in the gradient domain, in linear radiance: per surface, the step between the
photograph's side and the fill's side of the boundary (each a local mean over a band, so that
neither side's texture moves it) is spread over the filled pixels as a smooth membrane that is
the step at the boundary and varies slowly inside. The fill keeps its own gradients.
"""
from __future__ import annotations

import numpy as np

from ..light.radiosity import LUMA
from ..segmentation.masks import box_mean, dilate, rect_sum

# A boundary pixel's step is measured over the band within this share of the filled region's
# extent around it (in pixels, within the bounds), each side's band half as deep: wide enough
# that a texture's tiles, planks and grain average out on both sides.
_REACH, _MIN_REACH, _MAX_REACH = 1 / 3, 4, 24
# A texture's local means differ between two bands by themselves (a tile or a plank more in one,
# the gap between them in the other), and so does the light across a lit floor: a fill continuing
# both right still differs from the other side by as much. So a step is taken only as far as it
# stands out of the steps the surface around the hole shows between squares as far apart
# (beyond `_SIGNIFICANCE` times their spread), and averaged along the boundary over a reach. Where
# the fill continues the photograph's structure from copies (`continued`: a tiling's or planks'
# shifted copies, a wall's columns), its bands line up with the boundary as the photograph's do
# and their step has one sign along a whole straight edge (on basic_box's checker the truth's own,
# 0.064 of a floor at 0.18; a sheer curtain's bright folds beside a wall's columns on the real
# hotel, where one reach drew a pale patch): it is averaged over `_ALONG_CONTINUED` reaches.
# Elsewhere the light and the material's shade change along the border (a fill too dark at one
# end and right at the other), and that averaging lost the change: photo-textured apartment_chair
# at 512x256 (seeds 0-3, 128 samples) had its fill's mean error 0.058-0.066 at 2 reaches,
# 0.003-0.007 at 1; hotel_walls 0.234 -> 0.252, hotel_chair 0.059-0.070 -> 0.054-0.063, the others
# unchanged; half a reach put basic_box's checker filled without structure at 0.265 object +
# shadow error against 0.216 at 2 reaches, 1 reach at 0.230.
_ALONG = 1
_ALONG_CONTINUED = 2
# A fill synthesised per pixel on a texture that repeats nowhere (the structure stage searched it)
# leans bright: its exemplar leaves out what is darker than the material around the hole (clutter,
# the object's shadow, the nearer floor's other sheen found on one side only) and little that is
# brighter. Where it is brighter than the photograph on every side by less than the surface's own
# steps, no boundary pixel's step stands out, but their mean over the whole border does: its
# strips' texture is independent from one to the next, so the mean is tested against the spread
# over the square root of the strips the border holds. On the real lobby (a fill 0.034-0.075
# brighter all round, of 0.50, against strips that differ by 0.074) the step below the fill went
# from 0.528 / 0.492 to 0.494 / 0.492; photo-textured warehouse_box's mean error from
# 0.027-0.037 to 0.013-0.026, the other photo truths unchanged. Taken out both ways it darkened
# nothing wrongly but brightened hotel_chair's fill over the real armchair's printed shadow
# (0.054-0.063 -> 0.201-0.223) and apartment_chair's past its darker end (0.003-0.007 ->
# 0.033-0.045); on a tiling it does not hold (a checker's ring of tiles steps one way all round:
# basic_box filled per pixel went from 0.230 to 0.436 object + shadow error).
_SIGNIFICANCE = 1.0
# A texture's steps are rare but large (most pairs of strips lie within one tile): a high
# quantile of them, not their median, is what a boundary may show by chance.
_STEP_QUANTILE = 0.9
_ALIKE = 4.0  # within this factor of the boundary's median luminance: the surface's material
# The block seamless_block_change works in reaches past the filled pixels: the bands, the
# steps' averaging along the boundary and the surface's own steps around it all lie within.
_BLOCK_REACHES = 4
_AROUND = 2  # reaches: the surface around the hole whose own steps are measured


def seamless_change(radiance: np.ndarray, change: np.ndarray, filled: np.ndarray, surface: np.ndarray, *,
                    continued: np.ndarray | None = None, unrepeated: np.ndarray | None = None) -> np.ndarray:
    """(h, w, 3) `change` with the `filled` pixels' (h, w) step against the rest taken out, per
    `surface` (h, w, the surface id each pixel shows once the object is gone; -1: none), for a
    photograph `radiance` (h, w, 3). `continued` (h, w): the filled pixels that continue the
    photograph's structure from copies; `unrepeated` (h, w): those synthesised per pixel on a
    texture found to repeat nowhere (none of either where not given). Nothing changes outside
    `filled`; no radiance goes below 0."""
    out = np.array(change, dtype=np.float32, copy=True)
    edited = np.maximum(radiance, 0.0) + out
    luma = edited @ LUMA
    for s in np.unique(surface[filled]):
        if s < 0:
            continue
        inside = filled & (surface == s)
        outside = ~filled & (surface == s)
        rows, cols = np.nonzero(inside)
        reach = int(np.clip(_REACH * max(np.ptp(rows), np.ptp(cols), 1), _MIN_REACH, _MAX_REACH))
        band = max(reach // 2, 1)
        inner = inside & dilate(outside, band)
        outer = outside & dilate(inside, band)
        if not inner.any() or not outer.any():
            continue
        m_out, n_out = box_mean(edited, outer, reach)
        m_in, n_in = box_mean(edited, inner, reach)
        boundary = inside & dilate(outside, 1) & (n_out > 0) & (n_in > 0)
        if not boundary.any():
            continue
        # The surface's own steps are those of its material: not a desk or a rug's stripes beside it.
        typical = float(np.median(luma[outer]))
        alike = (luma > typical / _ALIKE) & (luma < typical * _ALIKE)
        spread = _step_spread(luma, outside & alike & dilate(inside, _AROUND * reach), reach, band)
        along = _ALONG_CONTINUED if continued is not None and continued[inside].mean() >= 0.5 else _ALONG
        step, _ = box_mean(np.where(boundary[..., None], m_out - m_in, 0.0), boundary, along * reach)
        kept = _kept(step @ LUMA, _SIGNIFICANCE * spread)
        step = step * kept[..., None]
        if unrepeated is not None and unrepeated[inside].mean() >= 0.5:
            brighter = np.minimum((m_out - m_in)[boundary].mean(axis=0), 0.0)
            strips = boundary.sum() / (2 * reach + 1)
            step += (1 - kept[..., None]) * _kept(brighter @ LUMA, spread / np.sqrt(max(strips, 1.0))) * brighter
        membrane = _pull_push(np.where(boundary[..., None], step, 0.0), boundary)
        out[inside] += membrane[inside].astype(np.float32)
    np.maximum(out, -np.maximum(radiance, 0.0), out=out)
    return out


def _kept(step: np.ndarray | float, noise: float) -> np.ndarray:
    """How much of a luminance `step` stands out of `noise`: 0 within it, towards 1 far beyond."""
    return np.clip(1 - (noise / np.maximum(np.abs(step), 1e-30)) ** 2, 0.0, 1.0)


def _step_spread(luma: np.ndarray, around: np.ndarray, reach: int, band: int) -> float:
    """How much the luminance `luma`'s (h, w) means over two adjacent strips `band` deep and `2 reach + 1`
    long (across or along the rows) differ where both lie mostly on the pixels `around`: the
    steps the surface shows by itself between bands like the boundary's, its light and texture.
    A high quantile, robust to a desk or a rug beside the hole being a minority of the pairs;
    infinite where too few such pairs are there."""
    luma = luma * around
    half = band // 2
    apart = 2 * half + 1
    steps = []
    for axis, sizes in ((0, (half, reach)), (1, (reach, half))):
        total, count = rect_sum(luma, *sizes), rect_sum(around.astype(np.float64), *sizes)
        full = count >= 0.5 * (2 * sizes[0] + 1) * (2 * sizes[1] + 1)
        mean = total / np.maximum(count, 1e-12)
        first = [slice(None), slice(None)]
        second = [slice(None), slice(None)]
        first[axis], second[axis] = slice(None, -apart), slice(apart, None)
        both = full[tuple(first)] & full[tuple(second)]
        steps.append(mean[tuple(first)][both] - mean[tuple(second)][both])
    step = np.concatenate(steps)
    if len(step) < 2 * reach:
        return float("inf")
    return float(np.quantile(np.abs(step - np.median(step)), _STEP_QUANTILE))


def _pull_push(values: np.ndarray, known: np.ndarray) -> np.ndarray:
    """(h, w, c) a smooth field through `values` where `known` (h, w): known pixels averaged into
    ever coarser levels, then every level's gaps filled from the next coarser, smoothed."""
    if known.all():
        return values
    if min(known.shape) <= 1:
        return np.where(known[..., None], values, values[known].mean(axis=0) if known.any() else 0.0)
    h, w = known.shape
    weight = known.astype(np.float64)
    pad = ((0, h % 2), (0, w % 2))
    wv = np.pad(values * weight[..., None], (*pad, (0, 0)))
    wp = np.pad(weight, pad)
    coarse_w = wp[0::2, 0::2] + wp[1::2, 0::2] + wp[0::2, 1::2] + wp[1::2, 1::2]
    coarse_v = wv[0::2, 0::2] + wv[1::2, 0::2] + wv[0::2, 1::2] + wv[1::2, 1::2]
    has = coarse_w > 0
    coarse = _pull_push(np.where(has[..., None], coarse_v / np.maximum(coarse_w, 1e-12)[..., None], 0.0), has)
    up = np.repeat(np.repeat(coarse, 2, axis=0), 2, axis=1)[:h, :w]
    smooth, _ = box_mean(up, np.ones((h, w)), 1)
    return np.where(known[..., None], values, smooth)


def seamless_block_change(radiance: np.ndarray, change: np.ndarray, filled: np.ndarray, surface: np.ndarray, *,
                          continued: np.ndarray | None = None, unrepeated: np.ndarray | None = None) -> np.ndarray:
    """`seamless_change` over an image that does not wrap around (a window of the panorama), on
    the block around the filled pixels that the step and the surface's own steps are measured
    in: at full resolution the object's window is several times larger than that."""
    out = np.array(change, dtype=np.float32, copy=True)
    if not filled.any():
        return out
    margin = _BLOCK_REACHES * _MAX_REACH
    rows, cols = np.flatnonzero(filled.any(axis=1)), np.flatnonzero(filled.any(axis=0))
    block = (slice(max(rows[0] - margin, 0), rows[-1] + margin + 1),
             slice(max(cols[0] - margin, 0), cols[-1] + margin + 1))
    out[block] = seamless_change(radiance[block], out[block], filled[block], surface[block],
                                 continued=None if continued is None else continued[block],
                                 unrepeated=None if unrepeated is None else unrepeated[block])
    return out


def seamless_panorama_change(radiance: np.ndarray, change: np.ndarray, filled: np.ndarray, surface: np.ndarray, *,
                             continued: np.ndarray | None = None, unrepeated: np.ndarray | None = None
                             ) -> np.ndarray:
    """`seamless_block_change` over a whole lat-long panorama, turned by whole columns so that
    the block lies away from the u seam, where the image's columns wrap around."""
    out = np.array(change, dtype=np.float32, copy=True)
    if not filled.any():
        return out
    width = filled.shape[1]
    columns = np.flatnonzero(filled.any(axis=0))
    # the middle of the filled columns' widest gap is where the seam goes
    gaps = np.diff(np.concatenate([columns, [columns[0] + width]]))
    widest = int(np.argmax(gaps))
    turned = np.mod(int(columns[widest]) + int(gaps[widest]) // 2 + np.arange(width), width)
    out[:, turned] = seamless_block_change(radiance[:, turned], out[:, turned], filled[:, turned], surface[:, turned],
                                           continued=None if continued is None else continued[:, turned],
                                           unrepeated=None if unrepeated is None else unrepeated[:, turned])
    return out
