"""Each pixel's irradiance E with the object and its change dE once the object is gone: from
the coarse lattice, from a fine lattice near the object, and per pixel where the object
shadows an important sender."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry.mesh import Geometry
from ..light.formfactor import paired_point_to_triangle
from ..light.planner import neighbourhood
from ..light.transport import pair_visibility
from ..quality import Params
from ..report import Report
from .interpolation import interpolate
from .irradiance import before_and_after, fine_light
from .occlusion import Occlusion
from .propagation import Propagation
from .room import Room
from .significance import significant
from .target import Target
from .trace import Traced


@dataclass(frozen=True)
class LocalLight:
    """Per hit pixel: E (N, 3) with the object in place, and dE (N, 3) with every bounce of
    the change once it is gone."""

    e_h: np.ndarray
    de_h: np.ndarray


def local_light(geo: Geometry, target: Target, traced: Traced, occlusion: Occlusion, room: Room,
                propagation: Propagation, params: Params, rep: Report, callbacks: RunCallbacks) -> LocalLight:
    """Per-pixel E and dE after removal, exact where the object's shadow of a light falls."""
    db, split = propagation.db, propagation.split
    b = room.senders.radiosity
    imp = np.flatnonzero(room.important)
    corners_h, weights_h = room.pixels.corners_h, room.pixels.weights_h

    # The important senders' change is added per pixel below, exactly where it matters.
    def change(e: np.ndarray, e_after: np.ndarray, t: np.ndarray, t_w: np.ndarray) -> np.ndarray:
        return e_after - e - (t_w - t)[:, imp] @ b[imp]

    e_v, ea_v = before_and_after(room, db, split, room.t_with, room.t_without, split.t_with, split.t_without)
    e_h = interpolate(e_v, corners_h, weights_h)
    de_h = interpolate(change(e_v, ea_v, room.t_with, room.t_without), corners_h, weights_h)

    candidates = ~traced.hidden_h & ~room.pixels.emitter_h
    if target.planes:
        candidates &= np.isin(traced.obj_h, target.planes)
    candidate = np.flatnonzero(candidates)  # rows of the hit pixels that may be relit
    sig = significant(room.senders, imp, traced.points_h[candidate], e_h[candidate], target, params)
    near = neighbourhood(traced.points_h[candidate], target.centre, target.radius, reach=params.reach)
    rep.info["affected_pixels"] = int((sig.any(axis=1) | near).sum())
    if not (sig.any() or near.any()):
        rep.skip("local", "the object neither shadows nor lights any visible surface")
        return LocalLight(e_h, de_h)

    # Base for the pixel: the coarse lattice, or near the object a fine one (only the
    # vertices the pixels use): the split patches' sub-triangles beside the object light
    # the pixels near them unevenly, which coarse vertices would smear over a coarse patch.
    pair_row, pair_sender = np.nonzero(sig)
    s = imp[pair_sender]
    pix = candidate[pair_row]
    lattice_e = (weights_h[pix] * room.t_with[corners_h[pix], s[:, None]]).sum(axis=1)
    near_pixels = candidate[near]
    if len(near_pixels):
        fine = fine_light(geo, target, room, occlusion, db, split, traced.tri_h[near_pixels],
                          traced.hits.bary.reshape(-1, 2)[traced.hp[near_pixels]], callbacks)
        rep.info["fine_vertices"] = len(fine.t_with)
        e_h[near_pixels] = interpolate(fine.e, fine.corners, fine.weights)
        de_h[near_pixels] = interpolate(change(fine.e, fine.e_after, fine.t_with, fine.t_without), fine.corners,
                               fine.weights)
        row = np.full(len(traced.hp), -1)
        row[near_pixels] = np.arange(len(near_pixels))
        in_fine = row[pix] >= 0
        k = row[pix[in_fine]]
        lattice_e[in_fine] = (fine.weights[k] * fine.t_with[fine.corners[k], s[in_fine, None]]).sum(axis=1)
    _add_exact_shadows(e_h, de_h, traced, occlusion, room, pix, s, lattice_e, callbacks)
    rep.info["exact_pairs"] = len(s)
    return LocalLight(e_h, de_h)


def _add_exact_shadows(e_h: np.ndarray, de_h: np.ndarray, traced: Traced, occlusion: Occlusion, room: Room,
                       pix: np.ndarray, s: np.ndarray, lattice_e: np.ndarray, callbacks: RunCallbacks) -> None:
    """Replace, in the arrays being built, the lattice's share `lattice_e` of the pairs (pixel
    pix, important sender s) by exact form factors and sampled visibility."""
    b = room.senders.radiosity
    senders = room.senders
    f = paired_point_to_triangle(traced.points_h[pix], traced.normals_h[pix], senders.triangles[s], senders.normals[s])
    vis, vis_w = pair_visibility(traced.points_h, senders, pix, s, occlusion.removed, occlusion.others,
                                 callbacks.check)
    np.add.at(e_h, pix, (f * vis - lattice_e)[:, None] * b[s])
    np.add.at(de_h, pix, (f * (vis_w - vis))[:, None] * b[s])
