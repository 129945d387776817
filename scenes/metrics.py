"""Scores of an edited panorama against the rendered ground truth (numpy only).

Inputs are lat-long panoramas (H, W, 3), row 0 at the top: `input` (rendered with the object),
`truth` (rendered without it, same seed), `edit` (the engine's input + difference) and the
(H, W) bool `object_mask` of pixels that see the removed object.

The two renders share their random numbers, so where no path touched the object their noise is
identical, and |input - truth| there is (nearly) zero rather than twice the noise. Scores
compare luminance after a 3x3 box blur, which wraps around the u seam and clamps at the poles,
so single-pixel noise (where paths differ) weighs less than the lighting change. Sums run over
pixels, not solid angle: a panorama pixel is what the viewer sees.

Region A (`lighting_region`) is where the removal visibly changed the lighting: outside the
object mask dilated by `margin` px (2), where the blurred |Y_input - Y_truth| exceeds all of
- `rel` (2 %) of the blurred Y_truth: smaller changes are invisible;
- `abs_frac` (1 %) of the median blurred Y_truth: keeps dark pixels out, and scales with the
  exposure, so a rescaled scene gives the same region;
- `k_noise` (3) times the local noise of the blurred difference (`blurred_difference_noise`):
  where the two renders' paths differ, their noise differs, and at 16-64 samples single
  pixels there pass a 2 % test by chance; a noise-dominated A would pull every ratio to 1.
"""
from __future__ import annotations

import numpy as np

from addon.geometry.latlong import dilate  # part of this module's interface, used by the tests as metrics.dilate

_LUMA = np.array([0.2126, 0.7152, 0.0722])


def luminance(rgb: np.ndarray) -> np.ndarray:
    """(H, W) Rec.709 luminance Y = 0.2126 R + 0.7152 G + 0.0722 B, as float64."""
    return np.asarray(rgb, dtype=np.float64) @ _LUMA


def box_blur3(a: np.ndarray) -> np.ndarray:
    """3x3 mean over the first two axes: wraps around the u seam (axis 1), clamps at the poles."""
    return box_blur(a, 1)


def box_blur(a: np.ndarray, radius: int) -> np.ndarray:
    """(2 radius + 1)^2 mean over the first two axes: wraps around the u seam (axis 1), clamps at
    the poles."""
    a = np.asarray(a, dtype=np.float64)
    n = 2 * radius + 1
    v = np.concatenate([a[:1].repeat(radius, axis=0), a, a[-1:].repeat(radius, axis=0)], axis=0)
    c = np.cumsum(np.concatenate([np.zeros_like(v[:1]), v]), axis=0)
    v = (c[n:] - c[:-n]) / n
    return sum(np.roll(v, k, axis=1) for k in range(-radius, radius + 1)) / n


def band_pass(y: np.ndarray) -> np.ndarray:
    """Edges and lines a pixel or a few wide: box blur of radius 1 minus box blur of radius 4.
    Render noise is mostly below it, shading and plank colours mostly above."""
    return box_blur(y, 1) - box_blur(y, 4)


def structure_correlation(edit: np.ndarray, truth: np.ndarray, mask: np.ndarray) -> float:
    """Correlation over `mask` of the band-pass luminance of `edit` with the truth's: 1 where the
    fill's edges and lines run where they really do, 0 for a flat fill or lines out of phase
    (MAE rewards blur and a detail ratio any texture; this rewards only lines in place)."""
    a = band_pass(luminance(edit))[mask]
    b = band_pass(luminance(truth))[mask]
    a, b = a - a.mean(), b - b.mean()
    return float((a * b).sum() / max(np.sqrt((a * a).sum() * (b * b).sum()), 1e-30))


def _blurred_y(rgb: np.ndarray) -> np.ndarray:
    return box_blur3(luminance(rgb))


def _abs_floor(y_truth: np.ndarray, abs_frac: float) -> float:
    return abs_frac * float(np.median(y_truth))


def blurred_difference_noise(input: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """(H, W) local standard deviation of the noise in the 3x3-blurred Y_input - Y_truth.

    Estimated from the high-pass residual d - blur(d) of the per-pixel difference d, whose
    variance is 8/9 of the pixel noise variance for independent pixels; its local mean over
    5x5 px, divided by the 9 pixels a 3x3 blur averages, gives the blurred difference's noise.
    In the first and last row the clamped blur counts the edge row twice, which doubles the
    ratio of the blurred noise's variance to the residual's (15/81 / (60/81) vs 1/9 / (8/9)).
    """
    d = luminance(input) - luminance(truth)
    r = d - box_blur3(d)
    var = box_blur3(box_blur3(r * r)) / 8.0
    var[[0, -1]] *= 2.0
    return np.sqrt(var)


def lighting_region(input: np.ndarray, truth: np.ndarray, object_mask: np.ndarray,
                    rel: float = 0.02, abs_frac: float = 0.01, k_noise: float = 3.0,
                    margin: int = 2) -> np.ndarray:
    """(H, W) bool region A where removing the object changed the lighting beyond noise:
    outside the object mask dilated by `margin` px, blurred |Y_input - Y_truth| above
    max(`rel` * blurred Y_truth, `abs_frac` * its median, `k_noise` * local noise)."""
    yi, yt = _blurred_y(input), _blurred_y(truth)
    threshold = np.maximum(np.maximum(rel * yt, _abs_floor(yt, abs_frac)),
                           k_noise * blurred_difference_noise(input, truth))
    return (np.abs(yi - yt) > threshold) & ~dilate(object_mask, margin)


def lighting_error_ratio(input: np.ndarray, edit: np.ndarray, truth: np.ndarray,
                         object_mask: np.ndarray, region: np.ndarray | None = None) -> float:
    """sum_A |Y_edit - Y_truth| / sum_A |Y_input - Y_truth| (blurred Y): 1 = nothing fixed,
    0 = exactly the truth, above 1 = worse than not editing. Raises ValueError if A is empty."""
    if region is None:
        region = lighting_region(input, truth, object_mask)
    if not region.any():
        raise ValueError("the removal changed no lighting beyond the noise (region A is empty)")
    yi, ye, yt = _blurred_y(input), _blurred_y(edit), _blurred_y(truth)
    return float(np.abs(ye - yt)[region].sum() / np.abs(yi - yt)[region].sum())


def far_damage(input: np.ndarray, edit: np.ndarray, truth: np.ndarray, object_mask: np.ndarray,
               region: np.ndarray | None = None, margin: int | None = None,
               percentile: float = 99.9, abs_frac: float = 0.01) -> float:
    """How much further from the truth than the input the edit gets where it should change
    (almost) nothing: the `percentile` of (|Y_edit - Y_truth| - |Y_input - Y_truth|) /
    Y_truth (blurred Y, Y_truth floored as in region A) over pixels farther than `margin` px
    (default W/64, at least 4) from the object and 2 px from region A. <= 0: no damage."""
    if region is None:
        region = lighting_region(input, truth, object_mask)
    if margin is None:
        margin = max(4, input.shape[1] // 64)
    far = ~dilate(object_mask, margin) & ~dilate(region, 2)
    yi, ye, yt = _blurred_y(input), _blurred_y(edit), _blurred_y(truth)
    excess = (np.abs(ye - yt) - np.abs(yi - yt)) / np.maximum(yt, _abs_floor(yt, abs_frac))
    return float(np.percentile(excess[far], percentile))


def chromaticity(rgb: np.ndarray) -> np.ndarray:
    """(H, W, 3) rgb / (r + g + b) of the 3x3-blurred colour; grey where the sum is 0."""
    c = box_blur3(rgb)
    s = c.sum(axis=-1, keepdims=True)
    return np.where(s > 0.0, c / np.where(s > 0.0, s, 1.0), 1.0 / 3.0)


def bleeding_error(input: np.ndarray, edit: np.ndarray, truth: np.ndarray,
                   object_mask: np.ndarray,
                   region: np.ndarray | None = None) -> tuple[float, float]:
    """Colour error in region A as (input's, edit's): the mean over A, weighted by blurred
    Y_truth, of sum_c |chromaticity_c - chromaticity_c(truth)|. Colour bleeding from the object
    shows as the input's error; a good edit brings its own well below it."""
    if region is None:
        region = lighting_region(input, truth, object_mask)
    if not region.any():
        raise ValueError("the removal changed no lighting beyond the noise (region A is empty)")
    ct = chromaticity(truth)
    w = _blurred_y(truth)[region]

    def err(img: np.ndarray) -> float:
        e = np.abs(chromaticity(img) - ct).sum(axis=-1)[region]
        return float((e * w).sum() / w.sum())

    return err(input), err(edit)


def noise_floor(input: np.ndarray, truth: np.ndarray, object_mask: np.ndarray,
                region: np.ndarray | None = None) -> float:
    """The `lighting_error_ratio` of the input scaled per pixel by the 3x3 box-filtered ratio
    Y_truth / Y_input: the best an edit that is smooth at the 3 px scale can do, i.e. the
    noise left where the two renders' paths differ (a second seed would overstate it)."""
    yi = luminance(input)
    ratio = box_blur3(luminance(truth) / np.maximum(yi, np.finfo(np.float64).tiny))
    ideal = np.asarray(input, dtype=np.float64) * ratio[..., None]
    return lighting_error_ratio(input, ideal, truth, object_mask, region)


def summary(input: np.ndarray, edit: np.ndarray, truth: np.ndarray,
            object_mask: np.ndarray) -> dict[str, float]:
    """All scores at their defaults, for reports: region size, ratio, noise floor, far
    damage, bleeding (input and edit)."""
    region = lighting_region(input, truth, object_mask)
    bleed_in, bleed_edit = bleeding_error(input, edit, truth, object_mask, region)
    return {
        "region_pixels": int(region.sum()),
        "lighting_error_ratio": lighting_error_ratio(input, edit, truth, object_mask, region),
        "noise_floor": noise_floor(input, truth, object_mask, region),
        "far_damage": far_damage(input, edit, truth, object_mask, region),
        "bleeding_input": bleed_in,
        "bleeding_edit": bleed_edit,
    }


def detail_ratio(edit: np.ndarray, truth: np.ndarray, mask: np.ndarray) -> float:
    """Standard deviation over `mask` of the high-pass luminance Y - box_blur3(Y), edit / truth
    (1 = as much texture; a flat fill gives ~0, noise explosions > 1)."""
    def high_pass(rgb: np.ndarray) -> np.ndarray:
        y = luminance(rgb)
        return (y - box_blur3(y))[mask]

    return float(high_pass(edit).std() / max(high_pass(truth).std(), 1e-30))


def hidden_region_scores(input: np.ndarray, edit: np.ndarray, truth: np.ndarray,
                         object_mask: np.ndarray) -> dict[str, float]:
    """How well the region the object hid was filled, by the figures the ground-truth tests bound:

    - `mean_ratio`: mean Y_edit / mean Y_truth over the object's pixels (1 = same brightness);
    - `detail_ratio`: `detail_ratio` over those pixels;
    - `object_shadow_ratio`: the blurred-Y error sum over the object's pixels and region A
      together, edit / input (how much of the removal's whole error is left);
    - `structure`: `structure_correlation` over the object's pixels (tile and plank lines in
      phase with the truth's)."""
    y_in, y_ed, y_tr = luminance(input), luminance(edit), luminance(truth)
    region = lighting_region(input, truth, object_mask) | object_mask
    bi, be, bt = box_blur3(y_in), box_blur3(y_ed), box_blur3(y_tr)
    return {
        "mean_ratio": float(y_ed[object_mask].mean() / y_tr[object_mask].mean()),
        "detail_ratio": detail_ratio(edit, truth, object_mask),
        "object_shadow_ratio": float(np.abs(be - bt)[region].sum() / np.abs(bi - bt)[region].sum()),
        "structure": structure_correlation(edit, truth, object_mask),
    }


def relit_detail_ratio(input: np.ndarray, edit: np.ndarray, truth: np.ndarray, object_mask: np.ndarray, *,
                       gain: float = 1.5) -> tuple[float, int]:
    """How speckled the pixels the removal must brighten come out, and how many there are.

    Over the pixels outside the object (dilated 1 px) that the truth shows at least `gain`
    times as bright as the input (3 x 3 blurred luminance): the robust spread (median absolute
    deviation) of the luminance against its 3 x 3 mean, relative to that mean, edit / truth.
    1 = as much detail as the surface shows in full light; above 1 = the shadow's noise relit
    with it. Raises ValueError if no pixel is brightened that much."""
    y_in, y_tr = luminance(input), luminance(truth)
    brightened = (box_blur3(y_tr) >= gain * box_blur3(y_in)) & ~dilate(np.asarray(object_mask, dtype=bool), 1)
    if not brightened.any():
        raise ValueError(f"no pixel outside the object is {gain} times brighter in the truth")

    def spread(y: np.ndarray) -> float:
        relative = ((y - box_blur3(y)) / np.maximum(box_blur3(y), 1e-30))[brightened]
        return float(np.median(np.abs(relative - np.median(relative))))

    return spread(luminance(edit)) / max(spread(y_tr), 1e-30), int(brightened.sum())


def ghost_share(edit: np.ndarray, truth: np.ndarray, object_mask: np.ndarray, *, threshold: float = 0.3) -> float:
    """Share of the object's pixels (the true object's `object_mask`) where the edit is visibly
    off the truth: blurred |Y_edit - Y_truth| > `threshold` * blurred Y_truth. A proxy off the
    object can leave a sliver of the object itself where the hidden region missed it: few
    pixels in the ratios' sums, plainly visible in the picture. Raises ValueError if the mask
    is empty."""
    mask = np.asarray(object_mask, dtype=bool)
    if not mask.any():
        raise ValueError("the object mask is empty")
    ye, yt = _blurred_y(edit), _blurred_y(truth)
    return float((np.abs(ye - yt) > threshold * yt)[mask].mean())


def relocation_region(input: np.ndarray, moved: np.ndarray, empty: np.ndarray, old_mask: np.ndarray,
                      new_mask: np.ndarray, margin: int = 2) -> np.ndarray:
    """(H, W) bool: where a relocation must change the panorama. The object at its old place
    and at its new one (masks dilated by `margin` px, the silhouettes' mixed pixels), and the
    lighting each placement changes against the room without the object (`empty`): region A of
    the input (`input` vs `empty`) and of the truth (`moved` vs `empty`)."""
    return (dilate(old_mask, margin) | dilate(new_mask, margin)
            | lighting_region(input, empty, old_mask, margin=margin)
            | lighting_region(moved, empty, new_mask, margin=margin))


def relocation_error_ratio(input: np.ndarray, edit: np.ndarray, moved: np.ndarray, region: np.ndarray) -> float:
    """sum |Y_edit - Y_moved| / sum |Y_input - Y_moved| over `region` (blurred Y, as in
    `lighting_error_ratio`), `moved` being the render with the object at its new place: 1 =
    nothing moved, 0 = exactly the truth."""
    if not region.any():
        raise ValueError("the relocation region is empty")
    yi, ye, yt = _blurred_y(input), _blurred_y(edit), _blurred_y(moved)
    return float(np.abs(ye - yt)[region].sum() / np.abs(yi - yt)[region].sum())


def ring_error(input: np.ndarray, edited: np.ndarray, truth: np.ndarray, silhouette: np.ndarray, *,
               width_px: int) -> float:
    """sum |e_edit| / sum |e_input| over the ring of pixels within `width_px` px outside the
    (H, W) bool `silhouette` (the object's mask dilated by `width_px`, less the mask), where
    e is the local mean of Y_image - Y_truth over the ring's own pixels in a 3x3 window.

    The contact shadow beside an object is the sharpest lighting change the removal makes, so a
    solve at a coarser resolution than the panorama's shows here first, as error left over the
    first pixels off the silhouette. Averaging only over ring pixels keeps the fill of the hidden
    region (whose texture differs from the truth pixel by pixel) out of the ring's inner edge,
    and averaging the signed error before taking its size lets the renders' noise partly cancel
    where a blur of the edit's lighting does not. A ratio of sums, it compares panoramas of
    different sizes rendered at the same samples per pixel over the same `width_px`: an edit's
    errors beside a silhouette are pixel-sized at any size (the silhouette falls between pixels).
    1 = nothing fixed, 0 = the truth. Raises ValueError if the ring is empty."""
    ring = dilate(silhouette, width_px) & ~np.asarray(silhouette, dtype=bool)
    if not ring.any():
        raise ValueError("no pixel lies beside the silhouette")
    weight = box_blur3(ring.astype(np.float64))[ring]
    y_truth = luminance(truth)

    def local_error(image: np.ndarray) -> np.ndarray:
        return np.abs(box_blur3(np.where(ring, luminance(image) - y_truth, 0.0))[ring] / weight)

    return float(local_error(edited).sum() / local_error(input).sum())


def bruise_share(edit: np.ndarray, truth: np.ndarray, object_mask: np.ndarray, *, width_px: int = 0,
                 factor: float = 0.8, percentile: float = 1.0) -> float:
    """Share of the object's pixels (the hidden region) that the edit fills darker than anything
    the clean surface there shows: blurred Y_edit below `factor` times the `percentile` of the
    truth's blurred Y over the object's pixels (and `width_px` px around them). A fill that
    copies a chair's dark legs, a rug's black stripes or the object's own contact shadow into a
    light floor leaves such a bruise; render noise does not (the blur, and the percentile of the
    truth's own noisy pixels). The truth under the object is the clean surface: a ring around
    it takes in the clutter beside the object, the very source of the bruises it is to catch.
    Raises ValueError if the mask is empty."""
    mask = np.asarray(object_mask, dtype=bool)
    if not mask.any():
        raise ValueError("the object mask is empty")
    surface = _blurred_y(truth)[dilate(mask, width_px) if width_px else mask]
    darkest = factor * float(np.percentile(surface, percentile))
    return float((_blurred_y(edit)[mask] < darkest).mean())


#: The bounds a removal on a photo-textured room is held to (issue 33), per figure of
#: `clean_removal_scores`: (lowest, highest), None where there is no limit.
CLEAN_REMOVAL_BOUNDS: dict[str, tuple[float | None, float | None]] = {
    "total": (None, 0.2),
    "mean_error": (None, 0.05),
    "detail": (0.8, 1.2),
    "bruise_share": (None, 0.02),
    "far_damage": (None, 0.05),
}


def within_bounds(scores: dict[str, float], figures: tuple[str, ...] = tuple(CLEAN_REMOVAL_BOUNDS)) -> bool:
    """Whether each of `figures` in `scores` lies within `CLEAN_REMOVAL_BOUNDS`."""
    for figure in figures:
        lo, hi = CLEAN_REMOVAL_BOUNDS[figure]
        if (lo is not None and scores[figure] < lo) or (hi is not None and scores[figure] > hi):
            return False
    return True


def bounds_text(figures: tuple[str, ...] = tuple(CLEAN_REMOVAL_BOUNDS)) -> str:
    """'total <= 0.2, mean error <= 0.05, detail 0.8-1.2, ...': the bounds of `figures` in words."""
    def one(figure: str) -> str:
        lo, hi = CLEAN_REMOVAL_BOUNDS[figure]
        name = figure.replace("_", " ")
        return f"{name} <= {hi}" if lo is None else f"{name} {lo}-{hi}"
    return ", ".join(one(f) for f in figures)


def clean_removal_scores(input: np.ndarray, edit: np.ndarray, truth: np.ndarray,
                         object_mask: np.ndarray) -> dict[str, float]:
    """The figures a removal on a photo-textured room is held to:

    - `light`: `lighting_error_ratio` (NaN when the removal changed no lighting beyond noise);
    - `structure`, `detail`, `total`: `hidden_region_scores`' structure, detail ratio and
      object + shadow error ratio;
    - `mean_error`: |mean Y_edit / mean Y_truth - 1| over the object's pixels;
    - `far_damage`: `far_damage`;
    - `bruise_share`: `bruise_share`."""
    region = lighting_region(input, truth, object_mask)
    hidden = hidden_region_scores(input, edit, truth, object_mask)
    return {
        "light": lighting_error_ratio(input, edit, truth, object_mask, region) if region.any() else float("nan"),
        "structure": hidden["structure"],
        "detail": hidden["detail_ratio"],
        "mean_error": abs(hidden["mean_ratio"] - 1.0),
        "total": hidden["object_shadow_ratio"],
        "far_damage": far_damage(input, edit, truth, object_mask, region),
        "bruise_share": bruise_share(edit, truth, object_mask),
    }


def neighbour_patch_scores(input: np.ndarray, truth: np.ndarray, object_mask: np.ndarray) -> dict[str, float]:
    """`clean_removal_scores` of the truth itself with the object's pixels replaced by the
    truth's own neighbouring patch: the object's pixels shifted by its extent (plus 2 px) left,
    right, up or down, whichever scores the lowest total; shifts whose source overlaps the object
    (over 5 % of it) or leaves the panorama are skipped. The light is exactly right and the fill
    is the room's own surface beside the hole, so its `total` and `mean_error` are what a
    plausible texture that is not the hidden one scores: a reference for a fill's, not a bound
    (a fill that continues tiles or planks in phase can score lower). Adds `shift` (rows,
    columns). Raises ValueError if no shift fits."""
    mask = np.asarray(object_mask, dtype=bool)
    rows, cols = np.nonzero(mask)
    height, width = rows.max() - rows.min() + 3, cols.max() - cols.min() + 3
    best = None
    for dr, dc in ((0, width), (0, -width), (height, 0), (-height, 0)):
        if rows.min() + dr < 0 or rows.max() + dr >= mask.shape[0]:
            continue
        source = np.roll(mask, (-dr, -dc), axis=(0, 1))
        if (source & mask).sum() > 0.05 * mask.sum():
            continue
        edit = np.asarray(truth, dtype=np.float64).copy()
        edit[mask] = truth[(rows + dr, (cols + dc) % mask.shape[1])]
        scores = clean_removal_scores(input, edit, truth, mask)
        if best is None or scores["total"] < best["total"]:
            best = {**scores, "shift": (int(dr), int(dc))}
    if best is None:
        raise ValueError("no neighbouring patch of the object's size fits beside it")
    return best
