"""Plain-array description of a scene as the engine sees it (no bpy).

`addon.blender.reader` fills a `SceneData` from Blender; tests and the command line hand it
to the engine. Every array is numpy, world space, metres.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np


@dataclass
class SceneData:
    """Everything the removal needs, read once from Blender on the main thread.

    hdri: (H, W, 3) float32 linear radiance, row 0 = top of the panorama (v = 1, up); None
        while still to be read from `hdri_path` (`reader.read_scene(defer_file=True)`).
    rotation: (3, 3) matrix R; the world direction d samples the texture at R @ d
        (identity without a Mapping node).
    center: (3,) probe centre.
    triangles: (T, 3, 3) float64 world-space vertex positions of every mesh triangle.
    tri_object: (T,) int index into `object_names` for each triangle.
    object_names: names of the mesh objects, in index order.
    hdri_path: the world image's file path (for the report), may be empty.
    """

    hdri: np.ndarray | None
    rotation: np.ndarray
    center: np.ndarray
    triangles: np.ndarray
    tri_object: np.ndarray
    object_names: list[str]
    hdri_path: str = ""
    notes: list[str] = field(default_factory=list)

    def object_index(self, name: str) -> int:
        try:
            return self.object_names.index(name)
        except ValueError:
            raise KeyError(name) from None
