"""A removal's solved lighting, before the panorama is edited."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry.mesh import Geometry
from ..light.split import Split
from ..quality import Params
from ..segmentation.seen import SeenObject
from .interpolation import interpolate
from .irradiance import fine_light
from .occlusion import Occlusion
from .room import Room
from .target import Target
from .trace import Traced


@dataclass(frozen=True)
class Solution:
    """Every stage's result up to the new irradiance of each pixel: the panorama the room's
    radiosity was read from, the geometry and target, what the pixels see, the occluders, the
    room (as the first order left it), the change db (P, 3) of its patches with every bounce,
    the split patches, per hit pixel E (N, 3) with the object and the change dE (N, 3), and the
    object as the photograph shows it."""

    hdri: np.ndarray
    params: Params
    geo: Geometry
    target: Target
    traced: Traced
    occlusion: Occlusion
    room: Room
    db: np.ndarray
    split: Split
    e_h: np.ndarray
    de_h: np.ndarray
    seen: SeenObject | None = None  # the object as the photograph shows it (None: the proxy's silhouette)

    def irradiance(self, tri: np.ndarray, bary: np.ndarray, callbacks: RunCallbacks) -> np.ndarray:
        """(N, 3) E with the object in place at the points (geometry triangle, barycentric
        weights of vertices 1 and 2), on a fine lattice over those triangles: points on the
        object itself too, which the pixel stages leave out."""
        fine = fine_light(self.geo, self.target, self.room, self.occlusion, self.db, self.split, tri, bary, callbacks)
        return np.maximum(interpolate(fine.e, fine.corners, fine.weights), 0.0)
