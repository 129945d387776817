"""The radiance change of the pixels that keep their surface, from the ratio form
L' = L (E + dE) / E, with every guard counted."""
from __future__ import annotations

import numpy as np

from ..light.radiosity import LUMA, RHO_MAX
from ..report import Report
from .solution import Solution


def compose(solution: Solution, rep: Report) -> np.ndarray:
    """(N, 3) radiance change of the hit pixels (0 where the pixel is filled or shows a light)."""
    traced, e_h = solution.traced, solution.e_h
    apply = ~traced.hidden_h & ~solution.room.pixels.emitter_h
    return ratio_change(traced.panorama_rows(solution.hdri), e_h, solution.de_h, apply,
                        e_ref=reference_irradiance(e_h, apply), rep=rep)


def reference_irradiance(e: np.ndarray, apply: np.ndarray) -> float:
    """The median luminance of E over the pixels that are relit: what "E is ~0" is relative to."""
    return float(np.median(e[apply] @ LUMA)) if apply.any() else 0.0


def ratio_change(radiance: np.ndarray, e: np.ndarray, de: np.ndarray, apply: np.ndarray, *, e_ref: float,
                 rep: Report, out: np.ndarray | None = None) -> np.ndarray:
    """(N, 3) change of the radiance (N, 3) of pixels with irradiance E and change dE (N, 3)
    where `apply`, else 0; written into `out` (N, 3) when given (a band of the full-resolution
    difference, so it is not copied there afterwards).

    Where E is ~0 (against `e_ref`) the ratio means nothing and the pixel is left; where the
    pixel implies a reflectance above RHO_MAX, E is taken as large as that bound allows (a
    lamp's glare or a model error would otherwise turn into a huge relative change); a change
    that would make the radiance negative is clamped to black."""
    # LUMA in the arrays' own precision: a float64 vector would turn a float32 band's
    # product into a ten times slower mixed one.
    dark = (e @ LUMA.astype(e.dtype)) <= 1e-6 * max(e_ref, 1e-30)
    near_zero = np.flatnonzero(apply & dark)
    rep.guard("irradiance_near_zero_pixels", np.count_nonzero((np.abs(de[near_zero]) @ LUMA) > 0))
    apply = apply & ~dark
    # In place where it can be: a band of a 16K panorama is millions of pixels.
    e_eff = np.maximum(e, 1e-30)
    # The E that implies a reflectance of RHO_MAX: pi L / E > RHO_MAX wherever E is below it.
    floor = radiance * (np.pi / RHO_MAX)
    over = floor > e_eff
    rep.guard("reflectance_clamped_pixels", np.count_nonzero(apply & (over[:, 0] | over[:, 1] | over[:, 2])))
    np.maximum(e_eff, floor, out=e_eff)
    d = np.multiply(radiance, de, out=out)
    d /= e_eff
    d[np.flatnonzero(~apply)] = 0.0
    black = np.negative(radiance, out=floor)
    negative = d < black
    rep.guard("negative_radiance_clamped", np.count_nonzero(negative[:, 0] | negative[:, 1] | negative[:, 2]))
    return np.maximum(d, black, out=d)
