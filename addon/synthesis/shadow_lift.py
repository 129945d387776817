"""The object's shadow that the relighting left darker than its surface, lifted to the surface.

The ratio form relights each pixel by the model's change of light, so where the proxy's shadow
is shallower than the object's (a box for an armchair, whose seat and legs shade the floor
deeper and wider) the photographed shadow is relit too little, and a dark band stays beside the
fill. The fill's material tells which of the surface's cells that is (`Material.shadow`: joined
to the hole, darker than the material around, in the colours a shadow on it takes, smooth,
brightened by the relighting). Each is lifted by its deficit against the floor beside it,
channel by channel (its own level, the mean of the cells around it alike in luminance, against
the mean of the cells near it in the surface's colours outside the shadow, within the ring's
reach), so that its own texture is kept and it takes the floor's colour: the light left in a
shadow is the surface's own, bounced, and a shadow lifted by one factor stays more saturated
than the floor (an orange strip on the real lobby's wood). The level is the floor's beside the
shadow, not the exemplar's: a glossy floor's nearer side, more saturated, is no exemplar (its
colours are not found all around the hole), and lifted to the paler far floor the lobby's band
came out a pale wedge. The lift fades out over the shadow's penumbra, where it goes on below the
darkness that marks a cell as shadow and the relighting brightens it (`Material.penumbra`). The
panorama's pixels, finer than the raster's cells, are lifted each by its own deficit, so the
lift ends where the photographed shadow does.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..light.radiosity import LUMA
from ..segmentation.masks import box_mean, dilate, max_filter
from .material import RELIT, Material, ring_widths

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
# A proxy modelled by eye, a few centimetres off, casts its shadow as far off: the bound on the lift
# at a cell is the largest within this many cells. Without it the real hotel armchair's shadow
# kept a dark line 1-3 pixels wide along the fill where the box's shadow fades out sooner
# (E' / E 1.3-1.6 there against a deficit of 2.0).
_DISPLACED = 2
# A pixel's own level is the mean of the pixels around it within this factor of its luminance:
# one at a shadow's edge is not lifted for the lit floor beside it, nor the floor beside it for
# the shadow (a plain 3x3 mean lifted the first lit pixel by 14 % on the real hotel).
_ALIKE = 1.5


@dataclass(frozen=True)
class ShadowLift:
    """Per raster cell (h, w), what lifts the object's shadow that the relighting left darker
    than its surface: the `level` (h, w, 3) it is brought to, how much of the way (`weight`: 1
    on the shadow, fading out over its penumbra, and on the cells beside it) and, in luminance,
    at most `bound` (None: `_MAX_LIFT`). Each cell or pixel is lifted by its own deficit
    against the level (`lift_gain`), so the lift follows the shadow's edge at whatever resolution it
    is applied: a panorama's pixels, finer than the raster, are lifted pixel by pixel."""

    level: np.ndarray
    weight: np.ndarray
    bound: np.ndarray | None

    def raster_gain(self, values: np.ndarray, known: np.ndarray) -> np.ndarray:
        """(h, w, 3) the factor per channel that lifts the raster's `values` (h, w, 3) at its
        `known` cells; 1 elsewhere."""
        rows, cols = np.nonzero(known & (self.weight > 0))
        out = np.ones(values.shape)
        bound = None if self.bound is None else self.bound[rows, cols]
        out[rows, cols] = lift_gain(values, known, rows, cols, level=self.level[rows, cols],
                                    weight=self.weight[rows, cols], bound=bound)
        return out


def lift_gain(image: np.ndarray, valid: np.ndarray, rows: np.ndarray, cols: np.ndarray, *, level: np.ndarray,
              weight: np.ndarray, bound: np.ndarray | None) -> np.ndarray:
    """(N, 3) the factor per channel, 1 or more, that brings the pixels (`rows`, `cols`) of
    `image` (h, w, 3; `valid` (h, w) where it is measured), each by its own level
    (`_alike_mean`), `weight` (N,) of the way to `level` (N, 3), in luminance at most `bound`
    (N,; None: `_MAX_LIFT`)."""
    deficit = np.clip(level / np.maximum(_alike_mean(image, valid, rows, cols), 1e-9), 1.0, _MAX_LIFT)
    if bound is not None:
        luminance = np.maximum(deficit @ LUMA, 1.0)
        deficit = np.maximum(deficit * np.minimum(bound / luminance, 1.0)[:, None], 1.0)
    return 1 + (deficit - 1) * weight[:, None]


def _alike_mean(image: np.ndarray, valid: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """(N, 3) at the pixels (`rows`, `cols`) of `image` (h, w, 3), the mean of the `valid`
    pixels among their 3x3 neighbours whose luminance lies within `_ALIKE` of theirs: a
    pixel's own level, its grain averaged, not the other side of an edge beside it. Only those
    pixels are read: at full resolution the image is the object's whole window."""
    h, w = valid.shape
    own = np.maximum(image[rows, cols] @ LUMA, 1e-12)
    total, count = np.zeros((len(rows), 3)), np.zeros(len(rows))
    for dr in (-1, 0, 1):
        for dc in (-1, 0, 1):
            r, c = np.clip(rows + dr, 0, h - 1), np.clip(cols + dc, 0, w - 1)
            neighbour = image[r, c]
            ratio = np.maximum(neighbour @ LUMA, 1e-12) / own
            take = valid[r, c] & (ratio < _ALIKE) & (ratio > 1 / _ALIKE) & (r == rows + dr) & (c == cols + dc)
            total += np.where(take[:, None], neighbour, 0.0)
            count += take
    return np.where(count[:, None] > 0, total / np.maximum(count, 1)[:, None], image[rows, cols])


def shadow_lift(values: np.ndarray, known: np.ndarray, material: Material, hole: np.ndarray, *,
                relit: np.ndarray | None = None) -> ShadowLift | None:
    """What brings the known cells of `material`'s shadow beside `hole` (and, fading out, those
    just past it) to the colour and level of the floor beside them (`Material.beside`), for
    reflectance `values` (h, w, 3), in luminance at most the relighting's own change nearby
    (`relit`, h, w: E' / E, its largest within `_DISPLACED` cells) to the power `_DEEPER`; None
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
    # 1 on the shadow, falling linearly to 0 over its penumbra
    fade = max(reach // 2, 1)
    weight = shadow.astype(np.float64)
    for step in range(1, fade + 1):
        weight = np.maximum(weight, (1 - step / (fade + 1)) * (dilate(shadow, step) & material.penumbra))
    # The pixels at the shadow's edge are looked up between its cells and the next ones (the
    # floor's, the hole's): those carry its weight, each lifted only by its own deficit.
    weight = max_filter(weight, 1)
    # counted from the gate on the relighting's change, so that the lift sets in smoothly
    bound = None if relit is None else max_filter(np.maximum(relit / RELIT, 1.0), _DISPLACED) ** _DEEPER
    return ShadowLift(level=level, weight=weight, bound=bound)
