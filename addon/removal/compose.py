"""The radiance change of the pixels that keep their surface, from the ratio form
L' = L (E + dE) / E, with every guard counted."""
from __future__ import annotations

import numpy as np

from ..light.radiosity import LUMA, RHO_MAX
from ..report import Report
from .solution import Solution


def compose(solution: Solution, rep: Report) -> np.ndarray:
    """(N, 3) radiance change of the hit pixels (0 where the pixel is filled or shows a light).

    Where E is ~0 the ratio means nothing and the pixel is left; where the pixel implies a
    reflectance above RHO_MAX, E is taken as large as that bound allows (a lamp's glare or a
    model error would otherwise turn into a huge relative change); a change that would make
    the radiance negative is clamped to black."""
    traced, e_h, de_h = solution.traced, solution.e_h, solution.de_h
    radiance = traced.panorama_rows(solution.hdri)
    apply = ~traced.hidden_h & ~solution.room.pixels.emitter_h
    e_ref = float(np.median(e_h[apply] @ LUMA)) if apply.any() else 0.0
    dark = (e_h @ LUMA) <= 1e-6 * max(e_ref, 1e-30)
    rep.guard("irradiance_near_zero_pixels", int((apply & dark & (np.abs(de_h) @ LUMA > 0)).sum()))
    apply &= ~dark
    e = np.maximum(e_h, 1e-30)
    implied = np.pi * radiance / e
    over = implied > RHO_MAX
    rep.guard("reflectance_clamped_pixels", int((apply & over.any(axis=1)).sum()))
    e_eff = np.where(over, np.pi * radiance / RHO_MAX, e)
    d = np.where(apply[:, None], radiance * de_h / np.maximum(e_eff, 1e-30), 0.0)
    negative = radiance + d < 0.0
    rep.guard("negative_radiance_clamped", int(negative.any(axis=1).sum()))
    return np.where(negative, -radiance, d)
