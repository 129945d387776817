"""Irradiance before and after the removal at receivers: the coarse ones, or the vertices of a
fine lattice laid over the triangles where points need it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry.patches import build_lattice, levels_for_size
from ..light.split import Split
from ..side_by_side import both
from .interpolation import inset, interpolate
from .lit_room import LitRoom
from .room import Room


def before_and_after(room: Room, db: np.ndarray, split: Split, t: np.ndarray, t_w: np.ndarray,
                     ts: np.ndarray, ts_w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(E, E') at receivers with transport t, t_w from the patches and ts, ts_w from the split
    patches' sub-triangles (with and without the object): the room as photographed, and after
    removal with every bounce of the change db (P, 3)."""
    return t @ split.rest(room.senders.radiosity) + ts @ split.b, _after(room, db, split, t_w, ts_w)


def _after(room: Room, db: np.ndarray, split: Split, t_w: np.ndarray, ts_w: np.ndarray) -> np.ndarray:
    """E' at receivers with transport t_w from the patches and ts_w from the split patches'
    sub-triangles without the object (see `before_and_after`)."""
    return t_w @ (split.rest(room.senders.radiosity) + db) + ts_w @ (split.b + split.db)


@dataclass(frozen=True)
class FineLight:
    """Transport and irradiance at the vertices of a fine lattice, and where points find them."""

    t_with: np.ndarray  # (V, P) transport from the patches with the object
    t_without: np.ndarray  # (V, P) ... without it
    e: np.ndarray  # (V, 3) E as photographed
    e_after: np.ndarray  # (V, 3) E' after removal
    corners: np.ndarray  # (N, 3) rows of the vertices each point interpolates
    weights: np.ndarray  # (N, 3) their weights


#: Points beyond this many object radii from its centre take a lattice COARSER times wider:
#: the contact shadow and the split patches' uneven light lie within it, and farther out the
#: light changes over the object's size, not the pixel's, so there the fine lattice cost three
#: quarters of its vertices for nothing.
FAR_RADII = 1.6
COARSER = 3.0


def fine_light(lit: LitRoom, tri: np.ndarray, bary: np.ndarray, callbacks: RunCallbacks) -> FineLight:
    """Light at the vertices of a fine lattice (cells of about the target's `fine_cell`) over
    the triangles `tri`: only the vertices that the points (tri, bary) interpolate from;
    points farther than FAR_RADII object radii from it on one COARSER."""
    lattice = _fine_lattice(lit, tri, bary)
    callbacks.check()
    return _light_of(lattice.vertices, lattice.normals, lit, lattice.corners, lattice.weights, callbacks)


def light_after(lit: LitRoom, tri: np.ndarray, bary: np.ndarray, callbacks: RunCallbacks) -> np.ndarray:
    """(N, 3) E' after the removal at the points (tri, bary), from the fine lattice of
    `fine_light`: only the transport without the object is needed, so no ray is tested against
    the object (on the hotel photograph that halved the light at the points it hid)."""
    lattice = _fine_lattice(lit, tri, bary)
    callbacks.check()
    occlusion, room, split = lit.occlusion, lit.room, lit.split
    t_without, ts_without = both(
        lambda: occlusion.transport_without(lattice.vertices, lattice.normals, room.senders, callbacks),
        lambda: occlusion.transport_without(lattice.vertices, lattice.normals, split.senders, callbacks))
    return interpolate(_after(room, lit.db, split, t_without, ts_without), lattice.corners, lattice.weights)


@dataclass(frozen=True)
class _Lattice:
    """The fine lattice's vertices (V, 3) and their normals, and where points find them."""

    vertices: np.ndarray
    normals: np.ndarray
    corners: np.ndarray  # (N, 3) rows of the vertices each point interpolates
    weights: np.ndarray  # (N, 3) their weights


def _fine_lattice(lit: LitRoom, tri: np.ndarray, bary: np.ndarray) -> _Lattice:
    geo, target = lit.geo, lit.target
    v = geo.triangles[tri]
    points = v[:, 0] + bary[:, :1] * (v[:, 1] - v[:, 0]) + bary[:, 1:] * (v[:, 2] - v[:, 0])
    far = np.linalg.norm(points - target.centre, axis=1) > FAR_RADII * target.radius
    corners = np.zeros((len(tri), 3), dtype=np.int64)
    weights = np.zeros((len(tri), 3))
    vertices, normals = [], []
    for group, cell in ((~far, target.fine_cell), (far, COARSER * target.fine_cell)):
        idx = np.flatnonzero(group)
        if not len(idx):
            continue
        levels = np.zeros(len(geo.triangles), dtype=np.int64)
        tris_r = np.unique(tri[idx])
        levels[tris_r] = levels_for_size(geo.triangles[tris_r], cell, max_level=512)
        fine = build_lattice(geo.triangles, levels)
        _, at, weights[idx] = fine.locate(tri[idx], bary[idx])
        needed, inverse = np.unique(at, return_inverse=True)
        corners[idx] = sum(map(len, vertices)) + inverse.reshape(at.shape)
        vertices.append(inset(fine.vertices[needed], geo.triangles[fine.vertex_tri[needed]]))
        normals.append(geo.normals[fine.vertex_tri[needed]])
    return _Lattice(np.concatenate(vertices), np.concatenate(normals), corners, weights)


def point_light(points: np.ndarray, normals: np.ndarray, lit: LitRoom, callbacks: RunCallbacks) -> FineLight:
    """Light at the points (N, 3) themselves, each its own vertex: for the few pixels where
    even a fine lattice would blur what they show (beside the object's silhouette)."""
    n = len(points)
    return _light_of(points, normals, lit, np.repeat(np.arange(n)[:, None], 3, axis=1),
                     np.repeat([[1.0, 0.0, 0.0]], n, axis=0), callbacks)


def _light_of(points: np.ndarray, normals: np.ndarray, lit: LitRoom, corners: np.ndarray, weights: np.ndarray,
              callbacks: RunCallbacks) -> FineLight:
    # The split patches' transport beside the patches': beside a large object (the hotel's
    # armchair) it is a quarter of the lattice's time.
    (t_with, t_without), split = both(lambda: lit.occlusion.transport(points, normals, lit.room.senders, callbacks),
                                      lambda: lit.occlusion.transport(points, normals, lit.split.senders, callbacks))
    e, e_after = before_and_after(lit.room, lit.db, lit.split, t_with, t_without, *split)
    return FineLight(t_with, t_without, e, e_after, corners, weights)
