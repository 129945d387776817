"""The artist's mask read from an image file or a Blender image (any format Blender reads)."""
from __future__ import annotations

import os

import bpy
import numpy as np

from ..errors import DimredError
from ..segmentation.user_mask import UserMask, user_mask


def read_mask_file(path: str, panorama: tuple[int, int]) -> UserMask:
    """The mask in the image file `path` for a panorama of `panorama` = (width, height);
    DimredError when the file is missing, is no image Blender can read, or does not fit."""
    path = os.path.abspath(path)
    if not os.path.isfile(path):
        raise DimredError(f"no such mask file: {path}")
    try:
        image = bpy.data.images.load(path, check_existing=False)
    except RuntimeError:
        raise DimredError(f"the mask {path} is not an image Blender can read") from None
    try:
        return mask_of_image(image, panorama, source=path)
    finally:
        bpy.data.images.remove(image)


def mask_of_image(image: bpy.types.Image, panorama: tuple[int, int], *, source: str | None = None) -> UserMask:
    """The mask painted in a Blender image (its values as stored: white adds, black takes away)."""
    source = source or f"image '{image.name}'"
    # Blender hands out an 8-bit image's code values / 255, without colour management: mid grey
    # as painted stays 0.5.
    width, height = image.size
    if width * height == 0 or (not image.has_data and not _loads(image)):
        raise DimredError(f"the mask {source} is not an image Blender can read")
    flat = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(flat)
    pixels = flat.reshape(height, width, -1)[::-1]
    return user_mask(pixels, panorama=panorama, source=source)


def _loads(image: bpy.types.Image) -> bool:
    try:
        image.reload()
        return len(image.pixels) > 0
    except RuntimeError:
        return False
