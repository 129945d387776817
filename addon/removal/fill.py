"""The pixels the object hid: reflectance synthesised on each revealed plane from the visible
reflectance around the hole, lit by the irradiance after the removal (L' = rho E' / pi)."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry import latlong
from ..geometry.planeraster import edge_direction
from ..light.radiosity import LUMA, RHO_MAX
from ..report import Report
from ..synthesis.plane_fill import FillOptions, HiddenPlane, PanoramaMaps, PanoramaReflectance, fill_surface
from ..synthesis.texture import SynthesisParams
from .interpolation import interpolate
from .irradiance import fine_light
from .room import MIN_COS
from .solution import Solution


@dataclass(frozen=True)
class _Revealed:
    """The revealed pixels' light: irradiance after removal, patch, and radiance as photographed."""

    e_after: np.ndarray  # (K, 3)
    patch: np.ndarray  # (K,)
    radiance: np.ndarray  # (K, 3)


def fill_hidden(solution: Solution, rep: Report, callbacks: RunCallbacks,
                show: Callable[[np.ndarray], None] | None = None) -> np.ndarray:
    """(K, 3) radiance change of the revealed pixels (those that saw the object and see a
    surface once it is gone): synthesised reflectance lit by the irradiance after removal.

    `show(change)` gets the revealed pixels' change as the fill refines: first with each
    patch's mean reflectance, then after every synthesis level of every surface."""
    geo, room, traced = solution.geo, solution.room, solution.traced
    behind = traced.behind
    radiance = traced.panorama_rows(solution.hdri)
    lit = _revealed_light(solution, radiance, callbacks)
    b = room.senders.radiosity
    rho = room.rho[lit.patch].copy()
    emit = room.emitter[lit.patch]

    def change() -> np.ndarray:
        new = rho * lit.e_after / np.pi
        # A light behind the object shines on with the radiosity its patch was given.
        new[emit] = b[lit.patch[emit]] / np.pi
        return new - lit.radiance

    if show is not None:
        show(change())
    panorama = _panorama_reflectance(solution, radiance)
    options = FillOptions(cell=_raster_cell(solution), margin=solution.params.exemplar_margin,
                          synthesis=SynthesisParams(neighbourhood=solution.params.synth_neighbourhood,
                                                    levels=solution.params.synth_levels,
                                                    generations=solution.params.synth_generations),
                          seed=solution.params.seed)
    keys = solution.target.surface_key
    surfaces = []
    for key in np.unique(keys[behind.tri]):
        sel = np.flatnonzero(keys[behind.tri] == key)
        callbacks.check()

        def level_shown(level_rho: np.ndarray, sel: np.ndarray = sel) -> None:
            rho[sel] = level_rho
            show(change())

        normal = geo.normals[behind.tri[sel[0]]]
        plane = HiddenPlane(surface=int(key), normal=normal, points=behind.points[sel],
                            along=edge_direction(geo.triangles[keys == key], normal))
        got = fill_surface(panorama, plane, options, cancel=callbacks.cancel,
                           progress=None if show is None else level_shown)
        name = geo.object_names[geo.tri_object[behind.tri[sel[0]]]]
        if got.known_cells:
            rho[sel] = got.rho
        if not got.synthesised:
            rep.warn(f"too little of '{name}' is seen around the object to synthesise its texture: "
                     f"{len(sel)} pixels get its mean reflectance")
        surfaces.append({"surface": name, "pixels": len(sel), "raster": list(got.raster_shape),
                         "cell": round(got.cell, 5), "known_cells": got.known_cells, "hole_cells": got.hole_cells,
                         "synthesised": got.synthesised})
    rep.info["filled_surfaces"] = surfaces
    return change()


def _revealed_light(solution: Solution, radiance: np.ndarray, callbacks: RunCallbacks) -> _Revealed:
    """The light of the revealed pixels, given every hit pixel's photographed radiance (N, 3)."""
    behind = solution.traced.behind
    fine = fine_light(solution.geo, solution.target, solution.room, solution.occlusion, solution.db,
                      solution.split, behind.tri, behind.bary, callbacks)
    patch, _, _ = solution.room.patches.lattice.locate(behind.tri, behind.bary)
    e_after = np.maximum(interpolate(fine.e_after, fine.corners, fine.weights), 0.0)
    return _Revealed(e_after, patch, radiance[behind.revealed])


def _panorama_reflectance(solution: Solution, radiance: np.ndarray) -> PanoramaReflectance:
    """rho = pi L / E wherever a pixel measures it (not hidden, not a light, not too dark), from
    the hit pixels' radiance L (N, 3); and the surfaces every pixel sees with the object and
    without it."""
    traced, room, e_h = solution.traced, solution.room, solution.e_h
    keys = solution.target.surface_key
    n = traced.height * traced.width
    shape = (traced.height, traced.width)
    surface_with = np.full(n, -1, dtype=np.int64)
    surface_with[traced.hp] = keys[traced.tri_h]
    tri_without = traced.behind.tri_without
    surface_without = np.where(tri_without >= 0, keys[np.maximum(tri_without, 0)], -1)
    maps = PanoramaMaps(surface_with.reshape(shape), traced.hits.distance, surface_without.reshape(shape),
                        traced.behind.distance_without.reshape(shape), traced.hidden_map)
    e_ref = float(np.median(e_h @ LUMA))
    measured = ~traced.hidden_h & ~room.pixels.emitter_h & ((e_h @ LUMA) > 1e-3 * e_ref)
    rho = np.zeros((n, 3))
    rho[traced.hp[measured]] = np.clip(np.pi * radiance[measured] / e_h[measured], 0.0, RHO_MAX)
    valid = np.zeros(n, dtype=bool)
    valid[traced.hp[measured]] = True
    return PanoramaReflectance(rho.reshape(*shape, 3), valid.reshape(shape), maps)


def _raster_cell(solution: Solution) -> float:
    """Raster cells about as large as the panorama's pixels where the object was."""
    traced, behind = solution.traced, solution.traced.behind
    width, height = traced.width, traced.height
    pix = traced.hp[behind.revealed]
    solid = np.broadcast_to(latlong.pixel_solid_angles(width, height), (height, width)).ravel()[pix]
    cos = np.abs(np.einsum("ij,ij->i", traced.hits.directions.reshape(-1, 3)[pix], solution.geo.normals[behind.tri]))
    footprint = np.sqrt(solid * behind.distance_without[pix] ** 2 / np.maximum(cos, MIN_COS))
    return float(np.median(footprint)) * solution.params.raster_cell
