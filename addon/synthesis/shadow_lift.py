"""The object's shadow that the relighting left darker than its surface, lifted to the surface.

The ratio form relights each pixel by the model's change of light, so where the proxy's shadow
is shallower than the object's (a box for an armchair, whose seat and legs shade the floor
deeper and wider) the photographed shadow is relit too little, and a dark band stays beside the
fill. The fill's material tells which of the surface's cells that is (`Material.shadow`: joined
to the hole, darker than the material around, in the colours a shadow on it takes, smooth,
brightened by the relighting). Each is lifted by its deficit against the floor beside it,
channel by channel (its 3x3 mean against the mean of the cells near it in the surface's colours
outside the shadow, within the ring's reach), so that its own texture is kept and it takes the
floor's colour: the light left in a shadow is the surface's own, bounced, and a shadow lifted by
one factor stays more saturated than the floor (an orange strip on the real lobby's wood). The
level is the floor's beside the shadow, not the exemplar's: a glossy floor's nearer side, more
saturated, is no exemplar (its colours are not found all around the hole), and lifted to the
paler far floor the lobby's band came out a pale wedge. The lift fades out over the shadow's
penumbra, where it goes on below the darkness that marks a cell as shadow and the relighting
brightens it (`Material.penumbra`).
"""
from __future__ import annotations

import numpy as np

from ..light.radiosity import LUMA
from ..segmentation.masks import box_mean, dilate
from .material import RELIT, Material, ring_widths

_LEVEL_RADIUS = 1  # cells: the shadow's level is its mean over 3x3 cells, its grain kept
# A shadow the proxy's shape left runs along a good share of the hole's border (in cells, at
# least this share of the border's); a few cells are the floor's own (a seam's end, a dark
# stripe's). On the photo-textured truths, whose proxies are exact, at most 0.033 (9 cells beside
# hotel_rug_box's box, whose lift raised its light error by up to 0.009); the real hotel
# armchair as a box, 0.23 (245 cells along 1065), 0.245 at the draft preset.
_MIN_SHADOW = 0.15
# The object's shadow is deeper than its proxy's by at most this power of the relighting's own
# change (E' / E, counted from the gate `RELIT` on it): a box for an armchair shades less than the
# armchair, but a cell the proxy hardly shades and that is far darker than the floor is something
# else's shadow or paint. On the real lobby and hotel the lift in the shadow is 1.40 and 1.76
# (medians) where the relighting gives 1.30 and 1.43; on the photo-textured hotel_chair the real
# armchair's shadow printed beside the chair, which the truth keeps, was lifted 2.2 (1.5 in its
# penumbra) where the chair's proxy gives 1.23 (1.09), 1.38 (1.02) now; its far damage rose from
# 0.047 to 0.050 without the bound (0.10-0.16 under rough proxies), 0.047 with it (1024x512, 16
# samples).
_DEEPER = 2.0
_MAX_LIFT = 4.0  # a cell is never brightened more than this (a deficit beyond is no shadow left by a proxy)


def shadow_gain(values: np.ndarray, known: np.ndarray, material: Material, hole: np.ndarray, *,
                relit: np.ndarray | None = None) -> np.ndarray | None:
    """(h, w, 3) the factor per channel (1 or more) that brings the known cells of `material`'s
    shadow beside `hole` (and, fading out, those just past it) to the colour and level of the
    floor beside them (`Material.beside`), for reflectance `values` (h, w, 3), in luminance at
    most the relighting's own change there (`relit`, h, w: E' / E) to the power `_DEEPER`; None
    where the material has no shadow there."""
    shadow = material.shadow
    if shadow is None or shadow.sum() < _MIN_SHADOW * (hole & dilate(~hole, 1)).sum():
        return None
    # the material around the hole, where the shadow was judged against it (the cells the
    # shadow's margin took out of the exemplar are not the material's level)
    around = material.around & material.exemplar
    if not around.any():
        return None
    reach = ring_widths(hole)[0]
    median = np.median(values[around], axis=0)
    beside = around if material.beside is None else material.beside
    near, count = box_mean(values, beside, reach)
    level = np.where(count[..., None] > 0, near, median)
    # a gloss's highlight nearby is no level to lift a shadow to: at most the material's median
    level *= np.minimum(float(median @ LUMA) / np.maximum(level @ LUMA, 1e-12), 1.0)[..., None]
    local, _ = box_mean(values, known, _LEVEL_RADIUS)
    deficit = np.clip(level / np.maximum(local, 1e-9), 1.0, _MAX_LIFT)
    if relit is not None:
        luminance = np.maximum(deficit @ LUMA, 1.0)
        # counted from the gate on the relighting's change, so that the lift sets in smoothly
        cap = np.maximum(relit / RELIT, 1.0) ** _DEEPER
        deficit = np.maximum(deficit * np.minimum(cap / luminance, 1.0)[..., None], 1.0)
    # 1 on the shadow, falling linearly to 0 over its penumbra
    fade = max(reach // 2, 1)
    weight = shadow.astype(np.float64)
    for step in range(1, fade + 1):
        weight = np.maximum(weight, (1 - step / (fade + 1)) * (dilate(shadow, step) & material.penumbra))
    gain = np.where(known[..., None], 1 + (deficit - 1) * weight[..., None], 1.0)
    # A pixel right outside the fill is looked up between the hole's cells and the shadow's: the
    # hole's cells beside the shadow take its gain, or the first row of pixels is lifted half way
    # and shows as a dotted dark line along the fill.
    carried, lifted_near = box_mean(gain, known & (weight > 0), 1)
    return np.where((~known & (lifted_near > 0))[..., None], carried, gain)
