"""The change of light carried around the room for several bounces: the relit floor and the
revealed footprint light every other surface, which light each other in turn."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..light.radiosity import propagate
from ..light.split import Split
from ..quality import Params
from ..report import Report
from .first_order import FirstOrder
from .occlusion import Occlusion
from .room import Room


@dataclass(frozen=True)
class Propagation:
    """(P, 3) total radiosity change db of the patches, all bounces (light sources keep theirs),
    and the split patches with their transport to the coarse receivers."""

    db: np.ndarray
    split: Split


def propagate_change(first: FirstOrder, occlusion: Occlusion, params: Params, rep: Report,
                     callbacks: RunCallbacks) -> Propagation:
    """Shoot the first change around the room until a bounce adds less than `bounce_tolerance`
    (or `max_bounces`); a split patch leaves its first change to its sub-triangles."""
    room, split = first.room, first.split
    split = split.with_transport(*occlusion.transport(room.receivers.points, room.receivers.normals, split.senders,
                                                      callbacks))
    total, bounces = shoot(room, split, first_change(room, first.de, split), split.db, params)
    rep.info["bounces"] = bounces
    rep.info["split_patches"] = len(np.unique(split.parent))
    return Propagation(total, split)


def first_change(room: Room, de: np.ndarray, split: Split) -> np.ndarray:
    """(P, 3) the first change of the patches' radiosity, rho dE: none for the object's patches
    and the lights, and none for a split patch (its sub-triangles carry its first change)."""
    db1 = room.rho * de
    db1[room.senders.on_removed | room.emitter] = 0.0
    db1[split.parent] = 0.0
    return db1


def shoot(room: Room, split: Split, db1: np.ndarray, sub_db1: np.ndarray, params: Params) -> tuple[np.ndarray, int]:
    """(P, 3) the change of the patches' radiosity over every bounce of a first change db1 (P, 3)
    of the patches and sub_db1 (M, 3) of the split's sub-triangles (whose transport the split
    holds), and the bounces it took. Linear in the first change."""
    p, m = len(room.areas), len(split.parent)

    # The sub-triangles send the first bounce only (reflectance 0): their light is gathered
    # by the patches, which carry every later bounce.
    def gather(db: np.ndarray) -> np.ndarray:
        e = room.patch_mean(room.t_without @ db[:p] + split.t_without @ db[p:])
        return np.concatenate([e, np.zeros((m, 3))])

    total, bounces = propagate(
        np.concatenate([db1, sub_db1]), np.concatenate([room.rho, np.zeros((m, 3))]),
        np.concatenate([room.areas, split.areas]), gather, tolerance=params.bounce_tolerance,
        max_bounces=params.max_bounces,
    )
    return total[:p], bounces
