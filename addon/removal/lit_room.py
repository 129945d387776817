"""The solved room the light stages read, as one value."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.mesh import Geometry
from ..light.split import Split
from .occlusion import Occlusion
from .room import Room
from .target import Target


@dataclass(frozen=True)
class LitRoom:
    """The room as the light stages see it: the geometry and the object to remove, the
    occluders, the room's patches (as the first order left them), the change db (P, 3) of their
    radiosity with every bounce, and the patches split beside the object."""

    geo: Geometry
    target: Target
    occlusion: Occlusion
    room: Room
    db: np.ndarray
    split: Split
