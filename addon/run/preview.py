"""What the world shows while a run computes: previews at preview size over what it showed
before (no bpy).

The world shows X = HDRI + the layer of the earlier results, at the panorama's full size. A
preview is small (`small_copy.preview_shape`), so it cannot simply add its difference to X:
the full-size panorama would still show the object's edges and texture through a difference
sixteen times coarser. So a preview has a mask, 1 on the object and a margin around it, where
its colour replaces X (the small edited panorama there), and 0 elsewhere, where its colour is
added to X (the change of light around the object, which is smooth). The world layer shows
X * (1 - mask) + colour (`operators.support.world_layer.show_preview`).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import small_copy
from .quick_preview import quick_difference

# Width the quick fill works at: its silhouette and fill take milliseconds there.
QUICK_WIDTH = 512


def blender_pixels(image: np.ndarray) -> np.ndarray:
    """(H, W, 3) top row first -> the flat RGBA float32 buffer `Image.pixels` takes (bottom row first)."""
    h, w = image.shape[:2]
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[..., :3] = image[::-1]
    return rgba.ravel()


@dataclass(frozen=True)
class Preview:
    """A preview as the main thread shows it: flat RGBA float32 buffers for `Image.pixels` of
    two `width` x `height` images, the colour and the mask (grey)."""

    color: np.ndarray
    mask: np.ndarray
    width: int
    height: int

    @classmethod
    def of(cls, color: np.ndarray, mask: np.ndarray) -> Preview:
        height, width = mask.shape
        return cls(blender_pixels(color), blender_pixels(np.repeat(mask[..., None], 3, axis=2)), width, height)


@dataclass(frozen=True)
class Previews:
    """What a run's previews are made of, at preview size."""

    panorama: np.ndarray  # (h, w, 3) HDRI + the earlier results: what the engine works on
    mask: np.ndarray  # (h, w) float32 in [0, 1]: where a preview replaces what the world shows
    previous: np.ndarray | None = None  # (h, w, 3) the object's own difference from a run before, in X

    @classmethod
    def quick(cls, panorama: np.ndarray, triangles: np.ndarray | None) -> tuple[Previews, Preview | None]:
        """The previews of a run on `panorama` (h, w, 3) and the first of them, the object
        (`triangles` (T, 3, 3) in the probe frame; None: not in the scene) filled from its
        surroundings (`quick_preview`)."""
        height, width = panorama.shape[:2]
        if triangles is None:
            return cls(panorama, np.zeros((height, width), dtype=np.float32)), None
        working = small_copy.resample(panorama, *small_copy.preview_shape(height, width, limit=QUICK_WIDTH))
        fill = quick_difference(working, triangles)
        mask = small_copy.resample(fill.hole.astype(np.float32)[..., None], height, width)[..., 0]
        inside = small_copy.resample(working + fill.difference, height, width)
        return cls(panorama, mask), Preview.of(mask[..., None] * inside, mask)

    def of_difference(self, difference: np.ndarray) -> Preview:
        """The preview of the engine's `difference` (H, W, 3), any size."""
        d = small_copy.resample(difference, *self.mask.shape)
        outside = d if self.previous is None else d - self.previous
        mask = self.mask[..., None]
        return Preview.of(mask * (self.panorama + d) + (1.0 - mask) * outside, self.mask)
