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
from .lit_room import LitRoom
from .occlusion import Occlusion
from .room import Room
from .target import Target
from .trace import Traced


@dataclass(frozen=True)
class Solution:
    """Every stage's result up to the new irradiance of each pixel: the panorama the room's
    radiosity was read from, the lit room, what the pixels see, per hit pixel E (N, 3) with the
    object and the change dE (N, 3), and the object as the photograph shows it."""

    hdri: np.ndarray
    params: Params
    lit: LitRoom
    traced: Traced
    e_h: np.ndarray
    de_h: np.ndarray
    seen: SeenObject | None = None  # the object as the photograph shows it (None: the proxy's silhouette)

    # The lit room's parts, which most stages read one or two of.
    @property
    def geo(self) -> Geometry:
        return self.lit.geo

    @property
    def target(self) -> Target:
        return self.lit.target

    @property
    def occlusion(self) -> Occlusion:
        return self.lit.occlusion

    @property
    def room(self) -> Room:
        return self.lit.room

    @property
    def db(self) -> np.ndarray:
        return self.lit.db

    @property
    def split(self) -> Split:
        return self.lit.split

    def irradiance(self, tri: np.ndarray, bary: np.ndarray, callbacks: RunCallbacks) -> np.ndarray:
        """(N, 3) E with the object in place at the points (geometry triangle, barycentric
        weights of vertices 1 and 2), on a fine lattice over those triangles: points on the
        object itself too, which the pixel stages leave out."""
        fine = fine_light(self.lit, tri, bary, callbacks)
        return np.maximum(interpolate(fine.e, fine.corners, fine.weights), 0.0)
