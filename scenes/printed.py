"""What a photo-textured truth printed under its removed object, against what it printed around it.

A photo-textured floor (`photo_texture`) carries the photograph's light and clutter as paint: the
floor under a removed box may be a printed sunlit patch, a rug's stripe or the contact shadow of
the real armchair that stood there. No fill drawn from what the panorama shows around the hole can
know that paint, so a truth's `mean_error` (`metrics.clean_removal_scores`) holds two things: how
far the fill is from the floor's level around it, and how far the paint under the object is from
that level. `printed_level` measures the second from the texture itself.
"""
from __future__ import annotations

from collections.abc import Callable

import numpy as np

from addon.geometry import latlong
from addon.geometry.raycast import first_hits
from addon.io.exr import read_exr
from addon.light.radiosity import LUMA
from addon.removal.target import scene_geometry
from addon.scene import SceneData

from .metrics import dilate
from .photo_texture import baked_floor
from .spec import SceneSpec

_AROUND = (2, 12)  # pixels from the object: the ring the floor around it is read in


def printed_level(spec: SceneSpec, scene: SceneData, mask: np.ndarray) -> float:
    """The mean albedo luminance of the photo-textured floor that `spec`'s removed object hides
    (`albedo_level`, with the floor texture baked for `spec`); NaN where its floor is not
    photo-textured. `scene` is the opened scene as the add-on reads it."""
    room, photo = spec.room, spec.room.floor.photo
    if photo is None:
        return float("nan")
    texture = read_exr(str(baked_floor(room, photo))) @ LUMA
    th, tw = texture.shape

    def albedo(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """The nearest texel's luminance at world (x, y), clamped to the room."""
        col = np.rint((x - room.lo[0]) / (room.hi[0] - room.lo[0]) * tw - 0.5).astype(np.int64)
        row = np.rint((room.hi[1] - y) / (room.hi[1] - room.lo[1]) * th - 0.5).astype(np.int64)
        return texture[np.clip(row, 0, th - 1), np.clip(col, 0, tw - 1)]

    return albedo_level(scene, mask, spec.remove, albedo)


def albedo_level(scene: SceneData, mask: np.ndarray, removed: str,
                 albedo: Callable[[np.ndarray, np.ndarray], np.ndarray]) -> float:
    """The mean `albedo(x, y)` (world floor coordinates) over the floor that the object `removed`
    hides (the pixels of its `mask` (h, w) that see the mesh named Floor once it is gone), over
    the mean over the floor seen 2-12 pixels around it: 1 where the floor under the object is
    painted at the level around it. NaN where neither side shows the floor."""
    h, w = mask.shape
    rows, cols = np.nonzero(dilate(mask, _AROUND[1]))
    geo = scene_geometry(scene)
    floor, index = scene.object_names.index("Floor"), scene.object_names.index(removed)
    directions = latlong.pixel_directions_at(rows, cols, w, h)
    kept = geo.tri_object != index
    # One trace without the object serves both sides: the pixels around it do not see it.
    hit, distance = first_hits(np.zeros_like(directions), directions, geo.triangles[kept])
    on_floor = (hit >= 0) & (geo.tri_object[kept][np.maximum(hit, 0)] == floor)
    inside = mask[rows, cols]
    hidden = inside & on_floor
    around = ~dilate(mask, _AROUND[0])[rows, cols] & on_floor
    if not hidden.any() or not around.any():
        return float("nan")
    world = (directions * distance[:, None]) @ np.asarray(scene.rotation, dtype=np.float64) + np.asarray(scene.center)
    level = np.asarray(albedo(world[:, 0], world[:, 1]), dtype=np.float64)
    return float(level[hidden].mean() / level[around].mean())
