"""Each pixel's irradiance E with the object and its change dE once the object is gone: from
the coarse lattice, from a fine lattice near the object, and per pixel where the object
shadows an important sender."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..light.formfactor import paired_point_to_triangle
from ..light.planner import neighbourhood
from ..light.radiosity import LUMA
from ..light.transport import pair_visibility
from ..quality import Params
from ..report import Report
from ..side_by_side import both
from .emitter_groups import GROUP_SAMPLES, emitter_groups, sample_counts
from .interpolation import interpolate
from .irradiance import FineLight, before_and_after, fine_light, point_light
from .lit_room import LitRoom
from .room import Room
from .shadow_cells import PairShadow, PixelGrid, cell_shadows
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
    grid: PixelGrid | None = None  # where the points lie in the panorama, for shadows traced per cell


def traced_receiving(traced: Traced, room: Room, target: Target) -> Receiving:
    """The working panorama's hit pixels as receivers."""
    relit = ~traced.hidden_h & ~room.pixels.emitter_h
    if target.planes:
        relit &= np.isin(traced.obj_h, target.planes)
    return Receiving(points=traced.points_h, normals=traced.normals_h, tri=traced.tri_h,
                     bary=traced.hits.bary.reshape(-1, 2)[traced.hp], corners=room.pixels.corners_h,
                     weights=room.pixels.weights_h, relit=relit,
                     grid=PixelGrid(traced.hp, traced.height, traced.width))


def local_light(lit: LitRoom, traced: Traced, params: Params, rep: Report, callbacks: RunCallbacks) -> LocalLight:
    """Per-pixel E and dE after removal, exact where the object's shadow of a light falls."""
    light = light_at(lit, traced_receiving(traced, lit.room, lit.target), params, callbacks)
    rep.info["affected_pixels"] = light.affected
    if light.affected == 0:
        rep.skip("local", "the object neither shadows nor lights any visible surface")
    else:
        rep.info["fine_vertices"] = light.fine_vertices
        rep.info["exact_pairs"] = light.exact_pairs
        rep.info["shadow_cells"] = {"cell": lit.target.shadow_cell, "tolerance": params.significance,
                                    "interpolated_points": light.interpolated_points,
                                    "computed_pairs": light.computed_pairs}
        if light.emitters:
            rep.info["emitter_groups"] = {"patches": list(light.emitters), "rays_per_pixel": GROUP_SAMPLES
                                          * params.sender_samples**2}
    return LocalLight(light.e, light.de)


@dataclass(frozen=True)
class PointLight:
    """E and dE (N, 3) at receiving points, and what it took: the points the object affects,
    the fine lattice's vertices, the (point, sender) pairs given exact shadows, the points
    that took them from their cell's corners and the pairs computed (`shadow_cells`)."""

    e: np.ndarray
    de: np.ndarray
    affected: int
    fine_vertices: int
    exact_pairs: int
    interpolated_points: int = 0
    computed_pairs: int = 0
    emitters: tuple[int, ...] = ()  # patches of each emitter of several important senders


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
    near = neighbourhood(receiving.points[candidate], target.centre, target.radius, reach=params.reach)
    # Base for the pixel: the coarse lattice, or near the object a fine one (only the
    # vertices the pixels use): the split patches' sub-triangles beside the object light
    # the pixels near them unevenly, which coarse vertices would smear over a coarse patch.
    # It is computed on a second thread while the significant pairs are found.
    near_pixels = candidate[near]

    def base() -> FineLight | None:
        if not len(near_pixels):
            return None
        if per_point:
            return point_light(receiving.points[near_pixels], receiving.normals[near_pixels], lit, callbacks)
        return fine_light(lit, receiving.tri[near_pixels], receiving.bary[near_pixels], callbacks)

    sig, fine = both(lambda: significant(room.senders, imp, receiving.points[candidate], e_h[candidate], target,
                                         params), base)
    affected = int((sig.any(axis=1) | near).sum())
    if not (sig.any() or near.any()):
        return PointLight(e_h, de_h, affected, 0, 0)

    fine_vertices = 0
    fine_row = np.full(len(receiving.points), -1)
    if fine is not None:
        fine_vertices = len(fine.t_with)
        e_h[near_pixels] = interpolate(fine.e, fine.corners, fine.weights)
        de_h[near_pixels] = interpolate(change(fine.e, fine.e_after, fine.t_with, fine.t_without), fine.corners,
                                        fine.weights)
        fine_row[near_pixels] = np.arange(len(near_pixels))

    def lattice_share(pix: np.ndarray, s: np.ndarray) -> np.ndarray:
        """(n,) the transport of the pairs (pixel pix, sender s) that E at the pixel holds."""
        share = (weights_h[pix] * room.t_with[corners_h[pix], s[:, None]]).sum(axis=1)
        in_fine = fine_row[pix] >= 0
        if in_fine.any():
            k = fine_row[pix[in_fine]]
            share[in_fine] = (fine.weights[k] * fine.t_with[fine.corners[k], s[in_fine, None]]).sum(axis=1)
        return share

    def shadow(pix: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """What replacing the lattice's share of the pairs by exact form factors and sampled
        visibility adds to E and dE (each (n, 3))."""
        f = paired_point_to_triangle(receiving.points[pix], receiving.normals[pix], room.senders.triangles[s],
                                     room.senders.normals[s])
        per_sender = np.array([samples.shape[1] for samples in room.senders.samples])[room.senders.group[s]]
        counts = sample_counts(groups, pix, s, f * (b[s] @ LUMA), per_sender)
        vis, vis_w = pair_visibility(receiving.points, room.senders, pix, s, lit.occlusion.removed,
                                     lit.occlusion.others, callbacks.check, counts=counts)
        return (f * vis - lattice_share(pix, s))[:, None] * b[s], (f * (vis_w - vis))[:, None] * b[s]

    groups = emitter_groups(room.senders, imp)
    pair_row, pair_sender = np.nonzero(sig)
    shadows = cell_shadows(receiving.points, receiving.normals, receiving.relit, receiving.grid,
                           candidate[pair_row], imp[pair_sender], params.significance * np.maximum(e_h @ LUMA, 0.0),
                           _on_two_threads(shadow), cell=target.shadow_cell)
    return PointLight(e_h + shadows.e, de_h + shadows.de, affected, fine_vertices, len(pair_row),
                      shadows.interpolated_points, shadows.computed_pairs,
                      tuple(groups.sizes[groups.sizes > 1].tolist()))


_THREADED_PAIRS = 20_000  # fewer pairs are computed on one thread: starting a second costs more


def _on_two_threads(shadow: PairShadow) -> PairShadow:
    """`shadow` computed on two threads, its pairs split between them by receiving point (a
    point's pairs stay together: they share its emitters' budget of rays): the same values.
    A window-lit room has hundreds of thousands of pairs to trace here, the box's lamps a few."""

    def split(pix: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        first = pix <= np.median(pix) if len(pix) >= _THREADED_PAIRS else np.ones(len(pix), dtype=bool)
        if first.all():
            return shadow(pix, s)
        e, de = np.empty((len(pix), 3)), np.empty((len(pix), 3))
        (e[first], de[first]), (e[~first], de[~first]) = both(lambda: shadow(pix[first], s[first]),
                                                              lambda: shadow(pix[~first], s[~first]))
        return e, de

    return split
