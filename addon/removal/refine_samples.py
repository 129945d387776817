"""Which of the full-resolution pixels refined get their light computed at their own point,
and how the others mix it, when the panorama is much finer than the working copy.

Some pixels take their own light, not the working copy's upsampled: those beside the object
(a contact shadow changes within one working pixel there) and those on a sharp shadow edge.
With four or more panorama pixels a working pixel, the light changes little from one pixel
to the next. So it is sampled on the pixels whose row and column are multiples of a stride,
half the working pixel's pitch (rounded down to a power of two: 2 at 4K, 4 at 8K from a 1K
working copy): each pixel mixes the samples of its cell bilinearly, those among the refined
pixels (or the object's window) on its own surface, and a pixel with none (the end of a
thin run, a corner of the room) is computed itself. The light there stays sampled at half
the working pixel's pitch or finer, twice as finely as the working copy's own pixels that
get their own light, for a quarter of the work at 4K and a sixteenth at 8K.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

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


def sample_stride(factor: int) -> int:
    """The samples' spacing in panorama pixels at `factor` panorama pixels a working pixel: half
    of it, rounded down to a power of two (1: every pixel is computed)."""
    return 1 << max(0, (max(1, factor) // 2).bit_length() - 1)


def refine_samples(pixel: np.ndarray, width: int, height: int, surface_at: SurfaceAt, *,
                   stride: int) -> RefineSamples:
    """How the refined flat panorama pixels `pixel` (N,) take their light from samples every
    `stride` pixels (see the module)."""
    rows, cols = np.divmod(pixel, width)
    own = surface_at(rows, cols)
    low_r, low_c = rows - rows % stride, cols - cols % stride
    fy, fx = (rows % stride) / stride, (cols % stride) / stride
    corner_r = np.stack([low_r, low_r, low_r + stride, low_r + stride], axis=1)
    corner_c = np.mod(np.stack([low_c, low_c + stride, low_c, low_c + stride], axis=1), width)
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
