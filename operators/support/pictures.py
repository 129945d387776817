"""The pictures the artist looks at or paints in an Image Editor: the diagnostics picture of how
the proxy fits the photograph, and the mask painted over the panorama.

"Dimred Diagnostics" is one image, updated in place after every run and Align to Photo, so an
Image Editor showing it follows along. It is packed: Blender then counts it as saved, so it
never asks about a modified image on quit, and like any image without users it is left out of
the .blend unless an Image Editor still shows it when the file is saved.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import bpy
import numpy as np

if TYPE_CHECKING:  # the engine is imported only when a run starts
    from ...addon.segmentation.seen import SeenObject

DIAGNOSTICS_IMAGE = "Dimred Diagnostics"


@dataclass(frozen=True)
class Picture:
    """An 8-bit sRGB picture: `image` (h, w, 3) uint8 top row first, and `pixels` the same as
    Blender's flat RGBA float buffer (bottom row first), made off the main thread."""

    image: np.ndarray
    pixels: np.ndarray

    @classmethod
    def of(cls, image: np.ndarray) -> Picture:
        h, w = image.shape[:2]
        rgba = np.ones((h, w, 4), dtype=np.float32)
        # An 8-bit image's pixels are its code values / 255, without colour management.
        rgba[..., :3] = image[::-1] / np.float32(255.0)
        return cls(image=image, pixels=rgba.ravel())

    @property
    def size(self) -> tuple[int, int]:
        return int(self.image.shape[1]), int(self.image.shape[0])


def diagnostics_picture(seen: SeenObject | None) -> Picture | None:
    """The diagnostics picture of the object as the photograph showed it (None: it did not)."""
    from ...addon.segmentation.diagnostics import picture_of

    return None if seen is None else Picture.of(picture_of(seen))


def show_diagnostics(picture: Picture, name: str = DIAGNOSTICS_IMAGE) -> bpy.types.Image:
    """Put `picture` into the image `name` (made, or resized, as needed)."""
    image = bpy.data.images.get(name)
    if image is None:
        image = bpy.data.images.new(name, *picture.size, alpha=False)
    elif tuple(image.size) != picture.size:
        image.scale(*picture.size)
    image.pixels.foreach_set(picture.pixels)
    image.update()
    image.pack()
    return image


def show_in_editor(context: bpy.types.Context, image: bpy.types.Image, *, paint: bool = False) -> bool:
    """Show `image` in an Image Editor (for painting, with `paint`): one that shows it already,
    else one that shows none of the add-on's images, else a new window. False where Blender has
    no window to show it in (background mode)."""
    areas = [area for window in context.window_manager.windows for area in window.screen.areas
             if area.type == 'IMAGE_EDITOR']
    ours = {DIAGNOSTICS_IMAGE, *(s.dimred.mask_image.name for s in bpy.data.scenes if s.dimred.mask_image)}
    area = (next((a for a in areas if a.spaces.active.image == image), None)
            or next((a for a in areas if a.spaces.active.image is None or a.spaces.active.image.name not in ours),
                    None))
    if area is None:
        if bpy.app.background or context.window is None:
            return False
        bpy.ops.wm.window_new()
        area = context.window_manager.windows[-1].screen.areas[0]
        area.type = 'IMAGE_EDITOR'
    space = area.spaces.active
    space.image = image
    if paint:
        space.ui_mode = 'PAINT'
    area.tag_redraw()
    return True
