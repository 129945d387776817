"""The object's shadow that the relighting left darker than its surface, lifted to the surface.

The ratio form relights each pixel by the model's change of light, so where the proxy's shadow
is shallower than the object's (a box for an armchair, whose seat and legs shade the floor
deeper and wider) the photographed shadow is relit too little, and a dark band stays beside the
fill. The fill's material tells which of the surface's cells that is (`Material.shadow`: joined
to the hole, darker than the material around, in its colour, smooth). Each is lifted by its
deficit against the material's level (its 3x3 mean against the median of the material around
the hole), so that its own texture is kept, and the lift fades out over its penumbra, where the
shadow goes on below the darkness that marks a cell as shadow (`Material.penumbra`: in the
material's colour, smooth and below its median, not a rug's crisp stripes beside it).
"""
from __future__ import annotations

import numpy as np

from ..light.radiosity import LUMA
from ..segmentation.masks import box_mean, dilate
from .material import Material, ring_widths

_LEVEL_RADIUS = 1  # cells: the shadow's level is its mean over 3x3 cells, its grain kept
# A shadow the proxy's shape left runs along a good share of the hole's border (in cells, at
# least this share of the border's); a few cells are the floor's own (a seam's end, a dark
# stripe's). On the photo-textured truths, whose proxies are exact, at most 0.033 (9 cells beside
# hotel_rug_box's box, whose lift raised its light error by up to 0.009); the real hotel
# armchair as a box, 0.23 (245 cells along 1065), 0.245 at the draft preset.
_MIN_SHADOW = 0.15
_MAX_LIFT = 4.0  # a cell is never brightened more than this (a deficit beyond is no shadow left by a proxy)


def shadow_gain(values: np.ndarray, known: np.ndarray, material: Material, hole: np.ndarray) -> np.ndarray | None:
    """(h, w) the factor (1 or more) that brings the known cells of `material`'s shadow beside
    `hole` (and, fading out, those just past it) to the level of the material around the hole,
    for reflectance `values` (h, w, 3); None where the material has no shadow there."""
    shadow = material.shadow
    if shadow is None or shadow.sum() < _MIN_SHADOW * (hole & dilate(~hole, 1)).sum():
        return None
    # the material's level around the hole, where the shadow was judged against it (the cells
    # the shadow's margin took out of the exemplar are not the material's level)
    around = material.around & material.exemplar
    if not around.any():
        return None
    y = values @ LUMA
    level = float(np.median(y[around]))
    local, _ = box_mean(y[..., None], known, _LEVEL_RADIUS)
    deficit = np.clip(level / np.maximum(local[..., 0], 1e-9), 1.0, _MAX_LIFT)
    # 1 on the shadow, falling linearly to 0 over its penumbra
    fade = max(ring_widths(hole)[0] // 2, 1)
    weight = shadow.astype(np.float64)
    for step in range(1, fade + 1):
        weight = np.maximum(weight, (1 - step / (fade + 1)) * (dilate(shadow, step) & material.penumbra))
    return np.where(known, 1 + (deficit - 1) * weight, 1.0)
