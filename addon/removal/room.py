"""The coarse radiosity solution of the room as photographed: patches, their radiosity read
from the panorama, the important senders, the transport to the coarse receivers, and the
reflectance, with estimates for what the probe cannot see."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry import latlong
from ..geometry.clusters import Clusters, cluster_triangles, visibility_samples
from ..geometry.mesh import Geometry
from ..geometry.patches import Lattice, build_lattice, levels_for_count, triangle_samples
from ..light.radiosity import LUMA, Reflectance, fill_unseen, patch_radiosity, recover_reflectance
from ..light.transport import Parts, Senders, make_senders
from ..quality import Params
from ..report import Report
from .interpolation import inset, interpolate
from .occlusion import Occlusion
from .target import Target
from .trace import Traced

MIN_COS = 0.05  # pixels seen more grazing than this count as if at this angle (area weight)
_VISIBLE = 0.2  # a patch is measured when pixels cover this share of its area


@dataclass(frozen=True)
class Patches:
    """The room's patches: the lattice's, then the removed object's clusters when it has many
    more triangles than its patch budget (then it is left out of the lattice)."""

    levels: np.ndarray  # (T,) lattice level of each triangle, 0 for a clustered object's
    lattice: Lattice
    patch_tri: np.ndarray  # (P,) the geometry triangle of each patch (one member of a cluster)
    corners: np.ndarray  # (P, 3) lattice vertices of each patch (zeros for clusters)
    triangles: np.ndarray  # (P, 3, 3)
    normals: np.ndarray  # (P, 3)
    areas: np.ndarray  # (P,)
    on_target: np.ndarray  # (P,) bool: the patch lies on the removed object
    object_tri: np.ndarray  # (n,) the object's triangles
    clusters: Clusters | None
    parts: Parts | None  # the clusters' member triangles, as senders of several triangles
    members: np.ndarray | None  # (C, m) each cluster's visibility sample triangles (rows of object_tri)
    member_weights: np.ndarray | None  # (C, m)


@dataclass(frozen=True)
class Receivers:
    """Coarse receivers: the room's lattice vertices (pixels interpolate between them), every
    patch's centroid and a cluster's visibility samples (whose mean stands for the patch)."""

    points: np.ndarray  # (R, 3)
    normals: np.ndarray  # (R, 3)
    vertex_row: np.ndarray  # (V,) receiver row of each lattice vertex
    patch_rows: np.ndarray  # (P, K) receiver rows whose weighted mean stands for each patch
    patch_weights: np.ndarray  # (P, K) their weights, summing to 1


@dataclass(frozen=True)
class PixelLookup:
    """Where each hit pixel takes its coarse light from."""

    patch_h: np.ndarray  # (N,) its patch
    corners_h: np.ndarray  # (N, 3) receiver rows of the lattice vertices it interpolates
    weights_h: np.ndarray  # (N, 3) their weights
    emitter_h: np.ndarray  # (N,) bool: it sees a light source


@dataclass(frozen=True)
class Room:
    """The coarse radiosity solution; `first_order` returns it with its patches near the object
    re-measured and resampled, which every later stage uses."""

    patches: Patches
    receivers: Receivers
    pixels: PixelLookup
    senders: Senders  # every patch as a sender, with its radiosity B (P, 3)
    important: np.ndarray  # (P,) bool: evaluated per pixel with exact visibility
    visible: np.ndarray  # (P,) bool: measured in the panorama
    emitter: np.ndarray  # (P,) bool
    rho: np.ndarray  # (P, 3)
    t_with: np.ndarray  # (R, P) receiver transport with the object
    t_without: np.ndarray  # (R, P) ... and without it

    @property
    def areas(self) -> np.ndarray:
        return self.patches.areas

    def patch_mean(self, receiver_values: np.ndarray) -> np.ndarray:
        """(P, C) each patch's value from the receivers' (R, C)."""
        return interpolate(receiver_values, self.receivers.patch_rows, self.receivers.patch_weights)


def solve_room(hdri: np.ndarray, geo: Geometry, target: Target, traced: Traced, occlusion: Occlusion,
               params: Params, rep: Report, callbacks: RunCallbacks) -> Room:
    """The room's patches, radiosity from the panorama, senders, transport and reflectance."""
    patches = _patches(geo, target, traced, params, rep)
    receivers = _receivers(geo, target, patches)
    patch_h, corners_h, weights_h = _pixel_lookup(traced, patches, receivers)
    b, visible = _measured(hdri, traced, patch_h, patches.areas, rep)
    senders, important = _senders(b, visible, geo, patches, params)
    callbacks.check()
    t_with, t_without = occlusion.transport(receivers.points, receivers.normals, senders, callbacks)
    b, rho, refl = _reflectance(b, visible, t_with, geo, target, patches, receivers)
    rep.guard("reflectance_clamped_patches", refl.clamped)
    rep.guard("irradiance_near_zero_patches", refl.guarded)
    rep.info.update(
        patches=len(patches.areas),
        important_senders=int(important.sum()),
        emitter_patches=int(refl.emitter.sum()),
        unseen_patches=int((~visible).sum()),
        coarse_receivers=len(receivers.points),
    )
    pixels = PixelLookup(patch_h, corners_h, weights_h, refl.emitter[patch_h])
    return Room(patches=patches, receivers=receivers, pixels=pixels, senders=senders.with_radiosity(b),
                important=important, visible=visible, emitter=refl.emitter, rho=rho, t_with=t_with,
                t_without=t_without)


def _patches(geo: Geometry, target: Target, traced: Traced, params: Params, rep: Report) -> Patches:
    on_target_tri = geo.tri_object == target.index
    levels = np.ones(len(geo.triangles), dtype=np.int64)
    levels[~on_target_tri] = levels_for_count(geo.triangles[~on_target_tri], params.patches)
    # An object of many more triangles than its patch budget is clustered instead of
    # subdivided (left out of the lattice; its patches come after the lattice's). A cluster
    # is sampled at patch_samples^2 of its triangles, so clustering pays only past that.
    obj = np.flatnonzero(on_target_tri)
    clustered = len(obj) > params.object_patches * params.patch_samples ** 2
    levels[obj] = 0 if clustered else levels_for_count(geo.triangles[obj], params.object_patches)
    lat = build_lattice(geo.triangles, levels)
    patch_tri, areas = lat.patch_tri, geo.areas[lat.patch_tri] / levels[lat.patch_tri] ** 2
    corners = lat.patch_corners
    clusters = parts = members = member_weights = None
    if clustered:
        seen = np.isin(obj, traced.tri_h)
        clusters = cluster_triangles(geo.triangles[obj].mean(axis=1), geo.normals[obj], geo.areas[obj],
                                     count=params.object_patches, size=target.radius, kind=seen)
        patch_tri = np.concatenate([patch_tri, obj[clusters.representative]])
        areas = np.concatenate([areas, clusters.area])
        corners = np.concatenate([corners, np.zeros((len(clusters.area), 3), dtype=np.int64)])
        parts = Parts(geo.triangles[obj], geo.normals[obj], lat.n_patches + clusters.label, params.aggregate_far)
        members, member_weights = visibility_samples(clusters, geo.triangles[obj].mean(axis=1), geo.areas[obj],
                                                     k=params.patch_samples ** 2)
        rep.info["object_clusters"] = len(clusters.area)
    triangles = np.concatenate([lat.patch_triangles(), geo.triangles[patch_tri[lat.n_patches:]]])
    return Patches(levels=levels, lattice=lat, patch_tri=patch_tri, corners=corners, triangles=triangles,
                   normals=geo.normals[patch_tri], areas=areas, on_target=on_target_tri[patch_tri], object_tri=obj,
                   clusters=clusters, parts=parts, members=members, member_weights=member_weights)


def _receivers(geo: Geometry, target: Target, patches: Patches) -> Receivers:
    """A patch is also received at its centroid: a vertex on the floor-wall edge would see the
    wall fill half its hemisphere and overstate the coupling of the whole patch."""
    lat, n_patches = patches.lattice, len(patches.areas)
    room_vertex = geo.tri_object[lat.vertex_tri] != target.index
    vertex_row = np.full(len(lat.vertices), 0, dtype=np.int64)
    vertex_row[room_vertex] = np.arange(room_vertex.sum())
    patch_rows = room_vertex.sum() + np.arange(n_patches)[:, None]
    patch_weights = np.ones((n_patches, 1))
    points = [inset(lat.vertices[room_vertex], geo.triangles[lat.vertex_tri[room_vertex]]),
              patches.triangles.mean(axis=1)]
    normals = [geo.normals[lat.vertex_tri[room_vertex]], patches.normals]
    if patches.clusters is not None:
        # A cluster's mean is taken over its visibility samples: its light varies over it.
        members, obj = patches.members, patches.object_tri
        first = room_vertex.sum() + n_patches
        patch_rows = np.repeat(patch_rows, members.shape[1], axis=1)
        patch_weights = np.pad(patch_weights, ((0, 0), (0, members.shape[1] - 1)))
        patch_rows[lat.n_patches:] = first + np.arange(members.size).reshape(members.shape)
        patch_weights[lat.n_patches:] = patches.member_weights / patches.member_weights.sum(axis=1, keepdims=True)
        points.append(geo.triangles[obj[members]].mean(axis=2).reshape(-1, 3))
        normals.append(geo.normals[obj[members]].reshape(-1, 3))
    return Receivers(np.concatenate(points), np.concatenate(normals), vertex_row, patch_rows, patch_weights)


def _pixel_lookup(traced: Traced, patches: Patches, receivers: Receivers
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Each hit pixel's patch, and the receiver rows and weights it interpolates. Pixels on a
    clustered object take their cluster (and no lattice vertices: hidden pixels are filled,
    not interpolated)."""
    n = len(traced.hp)
    in_lattice = patches.levels[traced.tri_h] > 0
    patch_h = np.zeros(n, dtype=np.int64)
    corners_h = np.zeros((n, 3), dtype=np.int64)
    weights_h = np.zeros((n, 3))
    patch_h[in_lattice], corners_h[in_lattice], weights_h[in_lattice] = patches.lattice.locate(
        traced.tri_h[in_lattice], traced.hits.bary.reshape(-1, 2)[traced.hp[in_lattice]])
    if patches.clusters is not None:
        tri_patch = np.zeros(len(patches.levels), dtype=np.int64)
        tri_patch[patches.object_tri] = patches.parts.owner
        patch_h[~in_lattice] = tri_patch[traced.tri_h[~in_lattice]]
    return patch_h, receivers.vertex_row[corners_h], weights_h


def pixel_areas(traced: Traced) -> tuple[np.ndarray, int]:
    """(N,) the surface area each hit pixel covers (so that means over a patch's pixels are over
    its area, not its pixels), and how many are seen so grazing that their weight is capped."""
    width, height, hp = traced.width, traced.height, traced.hp
    cos = np.abs(np.einsum("ij,ij->i", traced.hits.directions.reshape(-1, 3)[hp], traced.normals_h))
    solid = np.broadcast_to(latlong.pixel_solid_angles(width, height), (height, width)).ravel()[hp]
    dist = traced.hits.distance.ravel()[hp]
    return solid * dist**2 / np.maximum(cos, MIN_COS), int((cos < MIN_COS).sum())


def _measured(hdri: np.ndarray, traced: Traced, patch_h: np.ndarray, areas: np.ndarray, rep: Report
              ) -> tuple[np.ndarray, np.ndarray]:
    """(P, 3) radiosity of the patches as the panorama shows them (the area-weighted mean of
    their pixels) and (P,) whether enough of each is seen to count as measured. A pixel the
    photograph shows the object in though the proxy misses it would lend the surface behind it
    the object's colour, and one of the proxy the photograph shows no object in the object
    the surface's: neither counts."""
    weight, guarded = pixel_areas(traced)
    if guarded:
        rep.guard("grazing_pixels_weight_capped", guarded)
    weight[traced.beyond_h | traced.kept_h] = 0.0
    b, cover = patch_radiosity(traced.panorama_rows(hdri), patch_h, weight, areas)
    return b, cover >= _VISIBLE


def _senders(b: np.ndarray, visible: np.ndarray, geo: Geometry, patches: Patches, params: Params
             ) -> tuple[Senders, np.ndarray]:
    """The patches as senders, and (P,) which are important. Important senders are light
    sources and sunlit spots: much brighter than the typical surface, ranked by power (thesis
    4.3), sampled at sender_samples^2 points; the rest is gathered on the lattices."""
    areas, on_target, ptris = patches.areas, patches.on_target, patches.triangles
    power = (b @ LUMA) * areas
    bright = (b @ LUMA) > params.bright_factor * np.median((b @ LUMA)[visible & ~on_target])
    eligible = np.flatnonzero(visible & ~on_target & (power > 0) & bright)
    important = np.zeros(len(areas), dtype=bool)
    if len(eligible):
        order = eligible[np.argsort(-power[eligible])]
        share = np.cumsum(power[order]) / power[eligible].sum()
        count = min(int(np.searchsorted(share, params.sender_fraction) + 1), params.max_senders, len(order))
        important[order[:count]] = True
    imp_idx = np.flatnonzero(important)
    rest_idx = np.flatnonzero(~important)
    samples = [
        (imp_idx, triangle_samples(ptris[imp_idx], params.sender_samples)),
        (rest_idx, ptris[rest_idx].mean(axis=1)[:, None, :]),
    ]
    senders = make_senders(ptris, patches.normals, b, on_target, samples, patches.parts)
    if patches.clusters is not None:
        clusters = patches.lattice.n_patches + np.arange(len(patches.clusters.area))
        member_tris = geo.triangles[patches.object_tri[patches.members]]
        senders = senders.resampled(clusters, member_tris.mean(axis=2), patches.member_weights)
    return senders, important


def _reflectance(b: np.ndarray, visible: np.ndarray, t_with: np.ndarray, geo: Geometry, target: Target,
                 patches: Patches, receivers: Receivers) -> tuple[np.ndarray, np.ndarray, Reflectance]:
    """(P, 3) radiosity with the unseen patches estimated, (P, 3) reflectance rho = B / E, and
    the reflectance recovery's flags. A patch the probe does not see takes the reflectance of
    the seen part of its surface (or object) and radiosity rho E; three rounds let the
    estimates light each other."""
    b = b.copy()
    patch_rows, patch_weights = receivers.patch_rows, receivers.patch_weights
    # A light source outshines what it receives at every point; a patch partly under the
    # object may receive ~0 at its centroid only, so the test takes its brightest receiver.
    corner_rows = np.where(patches.on_target[:, None], patch_rows[:, :1], receivers.vertex_row[patches.corners])
    test_rows = np.concatenate([patch_rows, corner_rows], axis=1)
    e_all = t_with @ b
    e = interpolate(e_all, patch_rows, patch_weights)
    e_floor = 1e-9 * max(float((e @ LUMA).max()), 1e-30)
    keys = target.surface_key[patches.patch_tri]
    unseen = ~visible
    for _ in range(3):
        refl = recover_reflectance(b, e, visible, e_floor, e_test=(e_all @ LUMA)[test_rows].max(axis=1))
        measured = visible & ~refl.emitter & ((e @ LUMA) > e_floor)
        rho = fill_unseen(refl.rho, measured, [keys, geo.tri_object[patches.patch_tri]], patches.areas)
        rho[refl.emitter] = 0.0
        b[unseen] = rho[unseen] * e[unseen]
        e_all = t_with @ b
        e = interpolate(e_all, patch_rows, patch_weights)
    return b, rho, refl
