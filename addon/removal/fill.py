"""The pixels the object hid: reflectance synthesised on each revealed plane from the visible
reflectance around the hole, lit by the irradiance after the removal (L' = rho E' / pi)."""
from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry import latlong
from ..geometry.mesh import Geometry, surfaces_of
from ..geometry.planeraster import Frame, edge_direction
from ..light.radiosity import LUMA, RHO_MAX
from ..report import Report
from ..side_by_side import each
from ..synthesis.material import Material
from ..synthesis.plane_fill import (
    FillOptions,
    HiddenPlane,
    PanoramaMaps,
    PanoramaReflectance,
    SurfaceFill,
    fill_surface,
)
from ..synthesis.surface_edges import SurfaceEdges, SurfacePlane, find_surface_edges
from ..synthesis.texture import SynthesisParams
from .irradiance import light_after
from .near_reflectance import measuring
from .room import MIN_COS
from .solution import Solution


@dataclass(frozen=True)
class Revealed:
    """The pixels to fill (those that saw the object and see a surface once it is gone), at
    the resolution they are filled at, and the panorama's reflectance around them."""

    tri: np.ndarray  # (K,) the triangle each sees without the object
    bary: np.ndarray  # (K, 2) barycentric weights of its vertices 1 and 2 there
    points: np.ndarray  # (K, 3) the point it sees
    radiance: np.ndarray  # (K, 3) as photographed
    footprint: np.ndarray  # (K,) the pixel's edge projected on that surface
    panorama: PanoramaReflectance  # the exemplar's source
    edges: SurfaceEdges | None = None  # the surfaces' edges as the photograph shows them


@dataclass(frozen=True)
class HiddenLight:
    """The revealed pixels' light once the object is gone, and the radiosity of a light
    behind the object that they see."""

    e_after: np.ndarray  # (K, 3) irradiance after the removal
    emit: np.ndarray  # (K,) bool: the pixel sees a light
    emitted: np.ndarray  # (K, 3) that light's radiance (its patch's radiosity / pi)

    def change(self, rho: np.ndarray, radiance: np.ndarray) -> np.ndarray:
        """(K, 3) the radiance change of reflectance `rho` lit by E' against `radiance`."""
        new = rho * self.e_after / np.pi
        new[self.emit] = self.emitted[self.emit]
        return new - radiance


def hidden_light(solution: Solution, revealed: Revealed, callbacks: RunCallbacks) -> HiddenLight:
    """The irradiance after the removal at the revealed pixels (light transport: the report's
    stage `hidden_light`, apart from the synthesis of `filled_reflectance`)."""
    room = solution.room
    e_after = light_after(solution.lit, revealed.tri, revealed.bary, callbacks)
    patch, _, _ = room.patches.lattice.locate(revealed.tri, revealed.bary)
    emit = room.emitter[patch]
    emitted = np.zeros((len(patch), 3))
    # A light behind the object shines on with the radiosity its patch was given.
    emitted[emit] = room.senders.radiosity[patch[emit]] / np.pi
    return HiddenLight(e_after=np.maximum(e_after, 0.0), emit=emit, emitted=emitted)


@dataclass(frozen=True)
class FilledReflectance:
    """The revealed pixels' synthesised reflectance and what the seam and the shadow's lift need
    to know of how it was made."""

    rho: np.ndarray  # (K, 3)
    # over the pixels of the revealed panorama, the factor (h, w, 3) that lifts the object's
    # shadow the relighting left darker than its surface beside the hole (`shadow_lift`); None
    # where there is none
    lift: np.ndarray | None
    continued: np.ndarray  # (K,) bool: on a plane whose fill is `SurfaceFill.continued`
    # (K,) bool: on a plane synthesised per pixel where the structure stage found nothing that
    # repeats (not where it was not run)
    unrepeated: np.ndarray


def fill_hidden(solution: Solution, revealed: Revealed, light: HiddenLight, rep: Report, callbacks: RunCallbacks,
                show: Callable[[np.ndarray], None] | None = None) -> tuple[np.ndarray, FilledReflectance]:
    """(K, 3) radiance change of the revealed pixels: synthesised reflectance lit by the
    irradiance after removal (`light`); and the `filled_reflectance` it was made from.

    `show(change)` gets the revealed pixels' change as the fill refines: first with each
    patch's mean reflectance, then after every synthesis level of every surface and with each
    surface's final fill."""
    shown = None if show is None else (lambda rho: show(light.change(rho, revealed.radiance)))
    filled = filled_reflectance(solution, revealed, rep, callbacks, show=shown)
    return light.change(filled.rho, revealed.radiance), filled


def filled_reflectance(solution: Solution, revealed: Revealed, rep: Report, callbacks: RunCallbacks, *,
                       show: Callable[[np.ndarray], None] | None = None) -> FilledReflectance:
    """The reflectance of the revealed pixels, synthesised surface by surface (each patch's mean
    reflectance where a surface is too little seen). It needs no light, so a full-resolution
    removal computes the light after the removal meanwhile. `show(rho)` gets it as
    `fill_hidden`'s `show` says."""
    geo = solution.geo
    patch, _, _ = solution.room.patches.lattice.locate(revealed.tri, revealed.bary)
    rho = solution.room.rho[patch].copy()
    if show is not None:
        show(rho)
    options = FillOptions(cell=float(np.median(revealed.footprint)) * solution.params.raster_cell,
                          margin=solution.params.exemplar_margin,
                          synthesis=SynthesisParams(neighbourhood=solution.params.synth_neighbourhood,
                                                    levels=solution.params.synth_levels,
                                                    generations=solution.params.synth_generations),
                          seed=solution.params.seed, structure=solution.params.synth_structure)
    planes = hidden_planes(geo, solution.target.surface_key, revealed.tri, revealed.points)

    def fill(sel_plane: tuple[np.ndarray, HiddenPlane]) -> tuple[SurfaceFill, float]:
        """A plane's fill, and the seconds it took."""
        sel, plane = sel_plane
        callbacks.check()

        def level_shown(level_rho: np.ndarray) -> None:
            rho[sel] = level_rho
            show(rho)

        t0 = time.perf_counter()
        got = fill_surface(revealed.panorama, plane, options, cancel=callbacks.cancel,
                           progress=None if show is None else level_shown)
        return got, time.perf_counter() - t0

    # Without a preview to show level by level, the planes (the floor and the walls behind a
    # large object) are filled side by side: each is numpy on arrays of its own, and they are
    # taken in order afterwards. The hotel photograph's three took 1.65 s, now 1.13 s.
    fills = each(fill, planes) if show is None else map(fill, planes)  # with a preview, each shown as it comes
    surfaces, lift = [], None
    continued, unrepeated = np.zeros(len(rho), dtype=bool), np.zeros(len(rho), dtype=bool)
    for (sel, _), (got, seconds) in zip(planes, fills, strict=True):
        name = geo.object_names[geo.tri_object[revealed.tri[sel[0]]]]
        if got.known_cells:
            rho[sel] = got.rho
            if show is not None:  # with the photograph's fine detail, which the levels do not show
                show(rho)
        continued[sel] = got.continued
        unrepeated[sel] = (options.structure and got.synthesised and not got.continued and got.structured == 0
                           and got.band_cells == 0)
        if not got.synthesised:
            rep.warn(f"too little of '{name}' is seen around the object to synthesise its texture: "
                     f"{len(sel)} pixels get its mean reflectance")
        if got.synthesised and got.material.mostly_other:
            rep.warn(_material_warning(name, got.material))
        if got.band_cells:
            rep.warn(f"a band crossing the object on '{name}' (a painted lane, a rug, a strip between two floors) is "
                     f"continued through it as a straight strip: where it bends or ends under the object, turn "
                     f"Structure (synth_structure) off")
        surfaces.append({"surface": name, "pixels": len(sel), "raster": list(got.raster_shape),
                         "cell": round(got.cell, 5), "known_cells": got.known_cells, "hole_cells": got.hole_cells,
                         "synthesised": got.synthesised, "structured_cells": got.structured,
                         "band_cells": got.band_cells,
                         "exemplar": got.material.source, "exemplar_share": round(got.material.share, 3),
                         "shadow_lifted_pixels": got.lifted_pixels, "seconds": round(seconds, 4)})
        if got.lift is not None:  # a surface filled in parts lifts its pixels once
            lift = got.lift if lift is None else np.maximum(lift, got.lift)
    rep.info["filled_surfaces"] = surfaces
    if revealed.edges is not None and revealed.edges.edges:
        names = {int(k): geo.object_names[geo.tri_object[t]] for k, t in zip(*np.unique(solution.target.surface_key,
                                                                                       return_index=True), strict=True)}
        rep.info["surface_edges"] = [edge.describe(names) for edge in revealed.edges.edges]
    return FilledReflectance(rho=rho, lift=lift, continued=continued, unrepeated=unrepeated)


def lifted(radiance: np.ndarray, change: np.ndarray, lift: np.ndarray | None) -> np.ndarray:
    """`change` (h, w, 3) of `radiance` (h, w, 3) with the edited radiance multiplied by `lift`
    (h, w, 3; `filled_reflectance`) where it is above 1."""
    if lift is None:
        return change
    out = np.array(change, copy=True)
    at = (lift > 1).any(axis=-1)
    photographed = np.maximum(radiance[at], 0.0)
    out[at] = (photographed + change[at]) * lift[at] - photographed
    return out


def _material_warning(surface: str, material: Material) -> str:
    if material.source == "whole surface":
        return (f"nothing of '{surface}' seen around the object matches the material at its border: "
                f"the fill draws on the whole surface, clutter included")
    return (f"'{surface}' around the object is mostly unlike the material at its border (clutter, a rug, or the "
            f"same floor in another light or sheen): the fill draws only on the {material.share:.0%} that matches")


def hidden_planes(geo: Geometry, keys: np.ndarray, tri: np.ndarray, points: np.ndarray
                  ) -> list[tuple[np.ndarray, HiddenPlane]]:
    """The planes the revealed points (triangles `tri`, points (K, 3)) lie on, by surface
    key: which of the points each holds and the plane to synthesise."""
    planes = []
    for key in np.unique(keys[tri]):
        sel = np.flatnonzero(keys[tri] == key)
        normal = geo.normals[tri[sel[0]]]
        planes.append((sel, HiddenPlane(surface=int(key), normal=normal, points=points[sel],
                                        along=edge_direction(geo.triangles[keys == key], normal))))
    return planes


def working_revealed(solution: Solution) -> Revealed:
    """The revealed pixels of the working panorama, with its whole reflectance as exemplar; the
    pixels between a proxy's surface edge and the photograph's (`surface_edges`) on the surface
    the photograph shows there."""
    traced, behind = solution.traced, solution.traced.behind
    radiance = traced.panorama_rows(solution.hdri)
    pix = traced.hp[behind.revealed]
    edges = working_edges(solution)
    directions = traced.hits.directions.reshape(-1, 3)
    tri, bary, points = onto_photographed(edges, solution, directions[pix], behind.tri, behind.bary, behind.points)
    solid = np.broadcast_to(latlong.pixel_solid_angles(traced.width, traced.height),
                            (traced.height, traced.width)).ravel()[pix]
    footprint = surface_footprint(solid, directions[pix], solution.geo.normals[tri], np.linalg.norm(points, axis=1))
    return Revealed(tri=tri, bary=bary, points=points, radiance=radiance[behind.revealed], footprint=footprint,
                    panorama=_panorama_reflectance(solution, radiance, edges), edges=edges)


def filled_surfaces(solution: Solution, revealed: Revealed) -> np.ndarray:
    """(H, W) the surface each working pixel shows once the object is gone as the fill takes it
    (on the photograph's side of a surface edge: `working_revealed`), -1 for none."""
    traced = solution.traced
    surface = revealed.panorama.maps.surface_without.ravel().copy()
    surface[traced.hp[traced.behind.revealed]] = solution.target.surface_key[revealed.tri]
    return surface.reshape(traced.height, traced.width)


# Working pixels past the proxy's edge where a moved pixel takes its new surface's light: beside the corner.
_ACROSS = 1.5


def working_edges(solution: Solution) -> SurfaceEdges:
    """The edges between the room's surfaces near the hole as the working panorama shows them."""
    traced = solution.traced
    keys = solution.target.surface_key
    shape = (traced.height, traced.width)
    shows = np.full(traced.height * traced.width, -1, dtype=np.int64)
    shows[traced.hp] = keys[traced.tri_h]
    return surface_edges(solution, np.asarray(solution.hdri), shows.reshape(shape),
                         surfaces_of(keys, traced.behind.tri_without).reshape(shape), traced.hidden_map)


def surface_edges(solution: Solution, photo: np.ndarray, shows: np.ndarray, behind: np.ndarray, hidden: np.ndarray,
                  frame: Frame | None = None) -> SurfaceEdges:
    """The edges between the room's surfaces near the `hidden` pixels as the photograph `photo`
    (h, w, 3) shows them (`find_surface_edges`, over the pixels of `frame`, default the whole
    panorama), the surface key each pixel `shows` and sees `behind` the object given (h, w)."""
    geo, keys = solution.geo, solution.target.surface_key
    target = geo.tri_object == solution.target.index
    planes = {int(keys[t]): SurfacePlane(geo.normals[t], float(geo.normals[t] @ geo.triangles[t, 0]))
              for t in np.unique(keys, return_index=True)[1] if not target[t]}
    return find_surface_edges(photo, shows, behind, hidden, planes, frame=frame)


def onto_photographed(edges: SurfaceEdges, solution: Solution, directions: np.ndarray, tri: np.ndarray,
                       bary: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The revealed pixels' triangle, barycentric weights and point (unit `directions` (K, 3)),
    those the photograph shows on another surface than the proxy moved onto it: the point where
    their ray meets its plane, their light that of its triangle beside the proxy's corner."""
    keys = solution.target.surface_key
    moved, near, near_tri, _ = _moved(edges, solution, directions, keys[tri])
    if not len(moved):
        return tri, bary, points
    tri, bary, points = tri.copy(), bary.copy(), points.copy()
    normal = solution.geo.normals[near_tri]
    offset = np.einsum("ij,ij->i", normal, solution.geo.triangles[near_tri, 0])
    points[moved] = directions[moved] * (offset / np.einsum("ij,ij->i", directions[moved], normal))[:, None]
    tri[moved] = near_tri
    bary[moved] = _barycentric(near * (offset / np.einsum("ij,ij->i", near, normal))[:, None],
                               solution.geo.triangles[near_tri])
    return tri, bary, points


def _moved(edges: SurfaceEdges, solution: Solution, directions: np.ndarray, surface: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Which of the pixels (unit `directions` (K, 3) on `surface` (K,)) the photograph shows on
    another surface; where that surface's light is found for each (a direction beside the proxy's
    corner on it), the triangle seen there and its pixel (flat index); only those whose new
    surface is seen there."""
    traced = solution.traced
    moved = np.flatnonzero(edges.assign(directions, surface) != surface)
    if not len(moved):
        return moved, np.zeros((0, 3)), moved, moved
    new = edges.assign(directions[moved], surface[moved])
    near = edges.across(directions[moved], surface[moved], _ACROSS * np.pi / traced.height)
    row, col = latlong.uv_to_pixel(*latlong.direction_to_uv(near), traced.width, traced.height)
    pixel = row * traced.width + col
    near_tri = traced.behind.tri_without[pixel]
    ok = surfaces_of(solution.target.surface_key, near_tri) == new
    return moved[ok], near[ok], near_tri[ok], pixel[ok]


@dataclass(frozen=True)
class Across:
    """Seen pixels the photograph shows on the other side of a surface edge than the proxy: which
    of those given (`index`), the surface they are on, their distance to it and their reflectance."""

    index: np.ndarray  # (M,)
    surface: np.ndarray  # (M,) surface key
    distance: np.ndarray  # (M,)
    rho: np.ndarray  # (M, 3)


def moved_across(edges: SurfaceEdges, solution: Solution, directions: np.ndarray, surface: np.ndarray,
                 radiance: np.ndarray) -> Across:
    """Of the pixels that measure a reflectance (unit `directions` (K, 3) on `surface` (K,),
    photographed `radiance` (K, 3)), those the photograph shows on another surface (`edges`): on
    its plane, their irradiance that of the working pixel beside the proxy's corner on it (where
    that one measures a reflectance), at any resolution."""
    traced = solution.traced
    moved, _, near_tri, near_pixel = _moved(edges, solution, directions, surface)
    hit_row = np.full(traced.height * traced.width, -1, dtype=np.int64)
    hit_row[traced.hp] = np.arange(len(traced.hp))
    lit = hit_row[near_pixel]
    ok = (lit >= 0) & working_measured(solution)[np.maximum(lit, 0)]
    moved, lit, near_tri = moved[ok], lit[ok], near_tri[ok]
    normal = solution.geo.normals[near_tri]
    offset = np.einsum("ij,ij->i", normal, solution.geo.triangles[near_tri, 0])
    distance = offset / np.einsum("ij,ij->i", directions[moved], normal)
    rho = measured_reflectance(radiance[moved], solution.e_h[lit], np.ones(len(moved), dtype=bool))
    return Across(index=moved, surface=solution.target.surface_key[near_tri], distance=distance, rho=rho)


def _barycentric(points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """(K, 2) weights of vertices 1 and 2 of `triangles` (K, 3, 3) at `points` (K, 3) on their
    planes, clamped into the triangle."""
    v0 = triangles[:, 0]
    e1, e2, q = triangles[:, 1] - v0, triangles[:, 2] - v0, points - v0
    d11, d12, d22 = (np.einsum("ij,ij->i", a, b) for a, b in ((e1, e1), (e1, e2), (e2, e2)))
    q1, q2 = np.einsum("ij,ij->i", q, e1), np.einsum("ij,ij->i", q, e2)
    den = np.maximum(d11 * d22 - d12**2, 1e-30)
    w = np.clip(np.stack([(d22 * q1 - d12 * q2) / den, (d11 * q2 - d12 * q1) / den], axis=1), 0.0, 1.0)
    return w / np.maximum(w.sum(axis=1), 1.0)[:, None]


def surface_footprint(solid: np.ndarray, directions: np.ndarray, normals: np.ndarray, distance: np.ndarray
                      ) -> np.ndarray:
    """(K,) the edge of pixels of solid angle `solid` projected at `distance` along their unit
    `directions` onto surfaces with those `normals`."""
    cos = np.abs(np.einsum("ij,ij->i", directions, normals))
    return np.sqrt(solid * distance**2 / np.maximum(cos, MIN_COS))


def measured_reflectance(radiance: np.ndarray, e: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """(N, 3) rho = pi L / E where `measured`, else 0, clipped to the physical range."""
    return np.where(measured[:, None], np.clip(np.pi * radiance / np.maximum(e, 1e-30), 0.0, RHO_MAX), 0.0)


def working_measured(solution: Solution) -> np.ndarray:
    """(N,) bool: the hit pixels that measure a reflectance (not hidden, not a light, not too
    dark against the median irradiance)."""
    return measuring(solution.traced, solution.room.pixels.emitter_h, solution.e_h)


def _panorama_reflectance(solution: Solution, radiance: np.ndarray, edges: SurfaceEdges) -> PanoramaReflectance:
    """rho = pi L / E wherever a pixel measures it (not hidden, not a light, not too dark), from
    the hit pixels' radiance L (N, 3); and the surfaces every pixel sees with the object and
    without it. Pixels the photograph shows on the other side of a surface edge (`edges`) than
    the proxy are on that surface, their E that of the surface beside the proxy's corner."""
    traced, e_h = solution.traced, solution.e_h
    keys = solution.target.surface_key
    n = traced.height * traced.width
    shape = (traced.height, traced.width)
    surface_with = np.full(n, -1, dtype=np.int64)
    surface_with[traced.hp] = keys[traced.tri_h]
    surface_without = surfaces_of(keys, traced.behind.tri_without)
    distance_with = traced.hits.distance.ravel().copy()
    distance_without = traced.behind.distance_without.copy()
    measured = working_measured(solution)
    rho = np.zeros((n, 3))
    rho[traced.hp] = measured_reflectance(radiance, e_h, measured)
    valid = np.zeros(n, dtype=bool)
    valid[traced.hp[measured]] = True
    rows = np.flatnonzero(measured)
    directions = traced.hits.directions.reshape(-1, 3)[traced.hp[rows]]
    across = moved_across(edges, solution, directions, keys[traced.tri_h[rows]], radiance[rows])
    pixel = traced.hp[rows[across.index]]
    surface_with[pixel] = surface_without[pixel] = across.surface
    distance_with[pixel] = distance_without[pixel] = across.distance
    rho[pixel] = across.rho
    maps = PanoramaMaps(surface_with.reshape(shape), distance_with.reshape(shape), surface_without.reshape(shape),
                        distance_without.reshape(shape), traced.hidden_map)
    relit = np.ones(n, np.float32)
    relit[traced.hp] = relit_ratio(e_h, solution.de_h)
    return PanoramaReflectance(rho.reshape(*shape, 3), valid.reshape(shape), maps, relit.reshape(shape))


def relit_ratio(before: np.ndarray, change: np.ndarray) -> np.ndarray:
    """(...) the relighting's change of light E' / E in luminance, from E (..., 3) and its change,
    or from the radiance and its ratio-form change; 1 where `before` is 0."""
    luma = LUMA.astype(np.float32)
    b = before @ luma
    positive = b > 0
    return np.where(positive, (b + change @ luma) / np.where(positive, b, 1), 1).astype(np.float32)
