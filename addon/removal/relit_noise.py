"""The photograph's noise where the removal brightens a surface.

Relighting multiplies a pixel by its gain g = L' / L, and its texture should grow with it. But a
dark pixel's noise is larger against its signal than a bright one's (a sensor's shot and read
noise, a renderer's few paths into a shadow), so g times it is more than the lit surface around
shows: a relit contact shadow comes out speckled. How much more is measured on the panorama
itself, surface by surface: the relative detail (a relit pixel against its relit 3 x 3 mean) of
the pixels the removal raises, binned by gain, against that of the pixels of the same surface
nearby that it leaves. Its variance grows as v0 (1 + k (g - 1)); a raised pixel keeps its local mean and
its relit detail is weighed by 1 / sqrt(1 + k (g - 1)), which brings the detail's variance back
to v0. A photograph whose shadows are as clean as its lights (a bracketed HDR merge) gives k ~ 0
and is left as it is.

Only the relit pixels are quieted, not the exemplar the fill reads: noise and plank seams are
of one size in a deep shadow, so the weight takes both down, and a fill copying weakened seams
lost more detail than it gained structure (oak_chair at 1024x512: detail 0.90 -> 0.77).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..light.radiosity import LUMA
from ..report import Report

_REFERENCE = 0.05  # pixels whose gain is within this of 1 tell the surface's own detail
_BINS = np.array([1.05, 1.25, 1.5, 2.0, 3.0, np.inf])  # gains the raised pixels' detail is measured in
_MIN_PIXELS = 50  # pixels a gain bin, or a surface's reference, needs to be counted
_MAX_REFERENCE = 1 << 18  # reference pixels measured per surface, at most (an even subsample)
# the rendered ground truths measure 1.3-2.4; a small shadow's few bins can read far more
_MAX_GROWTH = 3.0
_NEGLIGIBLE = 0.01  # k (g - 1) below this weighs the detail by more than 0.995: the pixel is left
_MAD_TO_SD = 1.4826  # the median absolute deviation of a normal distribution, in standard deviations


@dataclass(frozen=True)
class QuietRelit:
    """The change (h, w, 3) with the raised pixels' excess noise taken out, the growth k
    measured per surface key and how many pixels were quieted."""

    change: np.ndarray
    growth: dict[int, float]
    pixels: int


def relit_noise_stage(radiance: np.ndarray, change: np.ndarray, surface: np.ndarray, *, enabled: bool,
                      rep: Report) -> QuietRelit:
    """`quiet_relit` as the removal's stage `relit_noise` (left out, as the parameter
    `match_relit_noise` allows), with what it did in the report."""
    with rep.stage("relit_noise"):
        if not enabled:
            rep.skip("relit_noise", "match_relit_noise is off: the relit pixels keep their noise times the gain")
            return QuietRelit(change=change, growth={}, pixels=0)
        quiet = quiet_relit(radiance, change, surface)
    rep.info["relit_noise"] = {"pixels": quiet.pixels,
                               "growth": {str(key): round(k, 3) for key, k in quiet.growth.items()}}
    return quiet


def quiet_relit(radiance: np.ndarray, change: np.ndarray, surface: np.ndarray) -> QuietRelit:
    """Match the noise of the pixels the removal brightens to their surface's.

    `radiance` (h, w, 3) is the photograph (>= 0), `change` (h, w, 3) the removal's change of
    it, `surface` (h, w) the surface key each pixel shows, -1 where its change is not a
    relighting (the object, a light, a pixel too dark to measure): those are left alone."""
    luma = LUMA.astype(radiance.dtype)
    relit = radiance + change
    y, after = radiance @ luma, relit @ luma
    usable = (surface >= 0) & (y > 0)
    gain = np.ones_like(y)
    gain[usable] = after[usable] / y[usable]
    growth: dict[int, float] = {}
    change = change.copy()
    quieted = 0
    measurable = usable & (gain >= _BINS[0])
    # Only surfaces with enough pixels brightened measurably can tell their noise's growth.
    keys, counts = np.unique(surface[measurable], return_counts=True)
    for key in keys[counts >= _MIN_PIXELS]:
        on_key = surface == key
        own = usable & on_key
        k = _growth(after, gain, surface, own, np.nonzero(measurable & on_key))
        if k <= 0.0:
            continue
        growth[int(key)] = k
        raised = np.nonzero(own & (k * (gain - 1.0) > _NEGLIGIBLE))
        if not len(raised[0]):
            continue
        g = gain[raised]
        # Detail against the relit neighbours: across a shadow's edge the photograph's own
        # neighbours differ by the shadow, not by noise.
        detail = relit[raised] - _local_mean(relit, surface, *raised)
        change[raised] -= detail * (1.0 - 1.0 / np.sqrt(1.0 + k * (g - 1.0)))[:, None]
        quieted += len(g)
    return QuietRelit(change=change, growth=growth, pixels=quieted)


def _growth(relit_y: np.ndarray, gain: np.ndarray, surface: np.ndarray, own: np.ndarray,
            measurable: tuple[np.ndarray, np.ndarray]) -> float:
    """k of one surface from the relit luminance (`own` its usable pixels, `measurable` those
    brightened by a gain of at least the first bin's, enough of them), 0 where too few
    unchanged pixels or bins tell it. The reference is the surface's unchanged pixels within
    the bounding box of the measurable ones (the shadow, not the whole surface the object took
    a little light from), grown by its own size: near enough to share their texture's scale in
    the panorama."""
    rows, cols = measurable
    h, w = relit_y.shape
    pad_r, pad_c = np.ptp(rows) + 1, np.ptp(cols) + 1
    box = (slice(max(rows.min() - pad_r, 0), min(rows.max() + pad_r + 1, h)),
           slice(max(cols.min() - pad_c, 0), min(cols.max() + pad_c + 1, w)))
    near = np.zeros_like(own)
    near[box] = own[box] & (np.abs(gain[box] - 1.0) < _REFERENCE)
    reference = np.nonzero(near)
    if len(reference[0]) < _MIN_PIXELS:
        return 0.0
    step = -(-len(reference[0]) // _MAX_REFERENCE)
    reference = (reference[0][::step], reference[1][::step])
    v0 = _robust_variance(_relative_detail(relit_y, surface, *reference))
    if v0 <= 0.0:
        return 0.0
    detail = _relative_detail(relit_y, surface, rows, cols)
    g = gain[measurable]
    which = np.digitize(g, _BINS) - 1
    num = den = 0.0
    for b in range(len(_BINS) - 1):  # a handful of bins, each a vectorised sum
        sel = which == b
        n = int(sel.sum())
        if n < _MIN_PIXELS:
            continue
        excess = float(g[sel].mean()) - 1.0
        num += n * (_robust_variance(detail[sel]) / v0 - 1.0) * excess
        den += n * excess * excess
    return float(np.clip(num / den, 0.0, _MAX_GROWTH)) if den > 0.0 else 0.0


def _relative_detail(y: np.ndarray, surface: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(n,) a pixel's luminance against its same-surface 3 x 3 mean, relative to that mean."""
    mean = _local_mean(y[..., None], surface, rows, cols)[:, 0]
    return (y[rows, cols] - mean) / np.maximum(mean, 1e-30)


def _local_mean(image: np.ndarray, surface: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(n, c) the mean of `image` (h, w, c) over each pixel's 3 x 3 neighbours on its own
    surface (the pixel itself included; the border clamped): a crease or the object's edge is
    not detail. Most pixels see one surface all round and take a plain box mean, summed in
    separable slices over their bounding box; the few beside another surface gather theirs."""
    h, w = surface.shape
    r0, c0 = int(rows.min()), int(cols.min())
    bh, bw = int(rows.max()) + 1 - r0, int(cols.max()) + 1 - c0
    rim_rows = np.clip(np.arange(r0 - 1, r0 + bh + 1), 0, h - 1)
    rim_cols = np.clip(np.arange(c0 - 1, c0 + bw + 1), 0, w - 1)
    box, keys = image[rim_rows][:, rim_cols], surface[rim_rows][:, rim_cols]
    band = box[:-2] + box[1:-1] + box[2:]
    mean = (band[:, :-2] + band[:, 1:-1] + band[:, 2:])[rows - r0, cols - c0] / 9.0
    own = keys[1:-1, 1:-1]
    one_surface = np.ones((bh, bw), dtype=bool)
    for dr in range(3):
        for dc in range(3):
            one_surface &= keys[dr:dr + bh, dc:dc + bw] == own
    mixed = np.flatnonzero(~one_surface[rows - r0, cols - c0])
    if len(mixed):
        mean[mixed] = _gathered_mean(image, surface, rows[mixed], cols[mixed])
    return mean.astype(image.dtype, copy=False)


def _gathered_mean(image: np.ndarray, surface: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(n, c) `_local_mean` of scattered pixels, each neighbour looked up."""
    h, w = surface.shape
    own = surface[rows, cols]
    total = np.zeros((len(rows), image.shape[2]))
    count = np.zeros(len(rows))
    for dr in (-1, 0, 1):  # nine offsets, each over all the pixels at once
        r = np.clip(rows + dr, 0, h - 1)
        for dc in (-1, 0, 1):
            c = np.clip(cols + dc, 0, w - 1)
            same = surface[r, c] == own
            total += image[r, c] * same[:, None]
            count += same
    return total / count[:, None]


def _robust_variance(values: np.ndarray) -> float:
    """The variance of `values` from their median absolute deviation (a few outliers, a shadow
    edge, do not move it)."""
    return float((_MAD_TO_SD * np.median(np.abs(values - np.median(values)))) ** 2)
