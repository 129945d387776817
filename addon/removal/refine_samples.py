"""Which of the full-resolution pixels refined get their light computed at their own point,
and how the others mix it, when the panorama is much finer than the working copy.

Some pixels take their own light, not the working copy's upsampled: those beside the object
(a contact shadow changes within one working pixel there) and those on a sharp shadow edge.
At MIN_FACTOR or more panorama pixels a working pixel, neighbouring pixels lie a quarter of a
working pixel apart or less, and their light differs by the little it changes over that step.
So they are sampled on the pixels of even row and column: each pixel mixes the samples at
most one pixel from it bilinearly, those among the refined pixels on its own surface, and a
pixel with none (the end of a thin run, a corner of the room) is computed itself. The light
there stays sampled at half the working pixel's pitch or finer, a quarter of the work at 8K.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

MIN_FACTOR = 4  # panorama pixels per working pixel from which the refined pixels are sampled
_STRIDE = 2

#: The surface key (n,) a pixel (rows, cols) shows where it can be a sample, -1 where not
#: (not among the pixels refined).
SurfaceAt = Callable[[np.ndarray, np.ndarray], np.ndarray]


@dataclass(frozen=True)
class RefineSamples:
    """For N refined pixels: the M flat pixels whose light is computed at their own point, and
    each pixel's mix of them (`corner` rows into `computed`, `weight` summing to 1, both
    (N, 4)). A pixel with no sample on its surface is among `computed` itself."""

    computed: np.ndarray
    corner: np.ndarray
    weight: np.ndarray


def refine_samples(pixel: np.ndarray, width: int, height: int, surface_at: SurfaceAt) -> RefineSamples:
    """How the refined flat panorama pixels `pixel` (N,) take their light (see the module)."""
    rows, cols = np.divmod(pixel, width)
    own = surface_at(rows, cols)
    low_r, low_c = rows - rows % _STRIDE, cols - cols % _STRIDE
    fy, fx = (rows % _STRIDE) / _STRIDE, (cols % _STRIDE) / _STRIDE
    corner_r = np.stack([low_r, low_r, low_r + _STRIDE, low_r + _STRIDE], axis=1)
    corner_c = np.mod(np.stack([low_c, low_c + _STRIDE, low_c, low_c + _STRIDE], axis=1), width)
    weight = np.stack([(1 - fy) * (1 - fx), (1 - fy) * fx, fy * (1 - fx), fy * fx], axis=1)
    inside = corner_r < height
    keys = np.full(corner_r.shape, -1, dtype=np.int64)
    keys[inside] = surface_at(corner_r[inside], corner_c[inside])
    weight = np.where((weight > 0) & (keys == own[:, None]) & (own >= 0)[:, None], weight, 0.0)
    total = weight.sum(axis=1)
    alone = total == 0
    corner_flat = corner_r * width + corner_c
    # A pixel alone is its own only corner, at full weight.
    corner_flat[alone, 0] = pixel[alone]
    weight[alone] = [1.0, 0.0, 0.0, 0.0]
    weight /= weight.sum(axis=1, keepdims=True)
    used = weight > 0
    computed, inverse = np.unique(corner_flat[used], return_inverse=True)
    corner = np.zeros(corner_flat.shape, dtype=np.int64)
    corner[used] = inverse
    return RefineSamples(computed=computed, corner=corner, weight=weight)
