"""Each pixel's irradiance E with the object and its change dE once the object is gone: from
the coarse lattice, from a fine lattice near the object, and per pixel where the object
shadows an important sender."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..light.formfactor import paired_point_to_triangle
from ..light.planner import neighbourhood
from ..light.transport import pair_visibility
from ..quality import Params
from ..report import Report
from .interpolation import interpolate
from .irradiance import before_and_after, fine_light, point_light
from .lit_room import LitRoom
from .occlusion import Occlusion
from .room import Room
from .significance import significant
from .target import Target
from .trace import Traced


@dataclass(frozen=True)
class LocalLight:
    """Per receiving point: E (N, 3) with the object in place, and dE (N, 3) with every
    bounce of the change once it is gone."""

    e_h: np.ndarray
    de_h: np.ndarray


@dataclass(frozen=True)
class Receiving:
    """Surface points whose light is wanted: the hit pixels of the working panorama, or the
    full-resolution pixels the upsampling cannot serve."""

    points: np.ndarray  # (N, 3) probe frame
    normals: np.ndarray  # (N, 3)
    tri: np.ndarray  # (N,) geometry triangle
    bary: np.ndarray  # (N, 2) barycentric weights of its vertices 1 and 2
    corners: np.ndarray  # (N, 3) receiver rows of the coarse lattice vertices each interpolates
    weights: np.ndarray  # (N, 3) their weights
    relit: np.ndarray  # (N,) bool: may change (not hidden, not a light, on a relit plane)


def traced_receiving(traced: Traced, room: Room, target: Target) -> Receiving:
    """The working panorama's hit pixels as receivers."""
    relit = ~traced.hidden_h & ~room.pixels.emitter_h
    if target.planes:
        relit &= np.isin(traced.obj_h, target.planes)
    return Receiving(points=traced.points_h, normals=traced.normals_h, tri=traced.tri_h,
                     bary=traced.hits.bary.reshape(-1, 2)[traced.hp], corners=room.pixels.corners_h,
                     weights=room.pixels.weights_h, relit=relit)


def local_light(lit: LitRoom, traced: Traced, params: Params, rep: Report, callbacks: RunCallbacks) -> LocalLight:
    """Per-pixel E and dE after removal, exact where the object's shadow of a light falls."""
    light = light_at(lit, traced_receiving(traced, lit.room, lit.target), params, callbacks)
    rep.info["affected_pixels"] = light.affected
    if light.affected == 0:
        rep.skip("local", "the object neither shadows nor lights any visible surface")
    else:
        rep.info["fine_vertices"] = light.fine_vertices
        rep.info["exact_pairs"] = light.exact_pairs
    return LocalLight(light.e, light.de)


@dataclass(frozen=True)
class PointLight:
    """E and dE (N, 3) at receiving points, and what it took: the points the object affects,
    the fine lattice's vertices and the (point, sender) pairs given exact visibility."""

    e: np.ndarray
    de: np.ndarray
    affected: int
    fine_vertices: int
    exact_pairs: int


def light_at(lit: LitRoom, receiving: Receiving, params: Params, callbacks: RunCallbacks, *,
             per_point: bool = False) -> PointLight:
    """E and dE at the receiving points, exact where the object's shadow of a light falls. Near
    the object the light comes from a fine lattice, or with `per_point` from each point's own
    transport."""
    room, target = lit.room, lit.target
    b = room.senders.radiosity
    imp = np.flatnonzero(room.important)
    corners_h, weights_h = receiving.corners, receiving.weights

    # The important senders' change is added per pixel below, exactly where it matters.
    def change(e: np.ndarray, e_after: np.ndarray, t: np.ndarray, t_w: np.ndarray) -> np.ndarray:
        return e_after - e - (t_w - t)[:, imp] @ b[imp]

    split = lit.split
    e_v, ea_v = before_and_after(room, lit.db, split, room.t_with, room.t_without, split.t_with, split.t_without)
    e_h = interpolate(e_v, corners_h, weights_h)
    de_h = interpolate(change(e_v, ea_v, room.t_with, room.t_without), corners_h, weights_h)

    candidate = np.flatnonzero(receiving.relit)  # the points that may be relit
    sig = significant(room.senders, imp, receiving.points[candidate], e_h[candidate], target, params)
    near = neighbourhood(receiving.points[candidate], target.centre, target.radius, reach=params.reach)
    affected = int((sig.any(axis=1) | near).sum())
    if not (sig.any() or near.any()):
        return PointLight(e_h, de_h, affected, 0, 0)

    # Base for the pixel: the coarse lattice, or near the object a fine one (only the
    # vertices the pixels use): the split patches' sub-triangles beside the object light
    # the pixels near them unevenly, which coarse vertices would smear over a coarse patch.
    pair_row, pair_sender = np.nonzero(sig)
    s = imp[pair_sender]
    pix = candidate[pair_row]
    lattice_e = (weights_h[pix] * room.t_with[corners_h[pix], s[:, None]]).sum(axis=1)
    near_pixels = candidate[near]
    fine_vertices = 0
    if len(near_pixels):
        fine = (point_light(receiving.points[near_pixels], receiving.normals[near_pixels], lit, callbacks)
                if per_point else fine_light(lit, receiving.tri[near_pixels], receiving.bary[near_pixels], callbacks))
        fine_vertices = len(fine.t_with)
        e_h[near_pixels] = interpolate(fine.e, fine.corners, fine.weights)
        de_h[near_pixels] = interpolate(change(fine.e, fine.e_after, fine.t_with, fine.t_without), fine.corners,
                                        fine.weights)
        row = np.full(len(receiving.points), -1)
        row[near_pixels] = np.arange(len(near_pixels))
        in_fine = row[pix] >= 0
        k = row[pix[in_fine]]
        lattice_e[in_fine] = (fine.weights[k] * fine.t_with[fine.corners[k], s[in_fine, None]]).sum(axis=1)
    _add_exact_shadows(e_h, de_h, receiving, lit.occlusion, room, pix, s, lattice_e, callbacks)
    return PointLight(e_h, de_h, affected, fine_vertices, len(s))


def _add_exact_shadows(e_h: np.ndarray, de_h: np.ndarray, receiving: Receiving, occlusion: Occlusion, room: Room,
                       pix: np.ndarray, s: np.ndarray, lattice_e: np.ndarray, callbacks: RunCallbacks) -> None:
    """Replace, in the arrays being built, the lattice's share `lattice_e` of the pairs (pixel
    pix, important sender s) by exact form factors and sampled visibility."""
    b = room.senders.radiosity
    senders = room.senders
    f = paired_point_to_triangle(receiving.points[pix], receiving.normals[pix], senders.triangles[s],
                                 senders.normals[s])
    vis, vis_w = pair_visibility(receiving.points, senders, pix, s, occlusion.removed, occlusion.others,
                                 callbacks.check)
    np.add.at(e_h, pix, (f * vis - lattice_e)[:, None] * b[s])
    np.add.at(de_h, pix, (f * (vis_w - vis))[:, None] * b[s])
