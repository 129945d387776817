"""The removal as a sequence of stages, each a function of the previous stages' frozen results:

    seen = photographed(...)            the object as the photograph shows it (segmented)
    geo, target = prepare(...)          the scene in the probe frame, the object to remove
    traced = trace(...)                 what every pixel sees, with the object and without it
    solution = solve_lighting(...)      occluders, room, first order, propagation, local light
    result = finish(...)                the ratio form where surfaces stay, the fill where it hid

`solve` runs the first three; a relocation runs them itself to insert its first guess of the
panorama between the trace and the light.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..callbacks import NO_CALLBACKS, RunCallbacks
from ..geometry.mesh import Geometry
from ..quality import Params
from ..report import Report
from ..scene import SceneData
from ..segmentation.seen import SeenObject, seen_object
from ..segmentation.user_mask import UserMask
from .compose import compose
from .fill import (
    FilledReflectance,
    fill_hidden,
    filled_surfaces,
    hidden_light,
    lifted,
    working_measured,
    working_revealed,
)
from .first_order import first_order
from .full_resolution import full_resolution
from .lit_room import LitRoom
from .local import local_light
from .near_reflectance import corrected_near_object
from .occlusion import occluders
from .propagation import propagate_change
from .relit_noise import relit_noise_stage
from .room import solve_room
from .seam import seamless_panorama_change
from .solution import Solution
from .target import Target, object_index, prepare, scene_geometry
from .trace import Traced, trace
from .working import downsample, working_size

STAGES = 11  # the stages a removal reports progress for


@dataclass(frozen=True)
class RemovalResult:
    difference: np.ndarray  # (H, W, 3) float32, top row first
    hidden_mask: np.ndarray  # (H, W) bool: pixels that showed the object
    report: dict
    hdri: np.ndarray  # (H, W, 3) the panorama the difference applies to
    seen: SeenObject | None = None  # the object as the photograph showed it (for the diagnostics picture)

    @property
    def edited(self) -> np.ndarray:
        """(H, W, 3) float32 hdri + difference: a new full-size array on every call (writers
        that stream take `edited_rows`)."""
        return self.edited_rows(0, self.difference.shape[0])

    def edited_rows(self, start: int, stop: int) -> np.ndarray:
        """Rows start:stop of the edited panorama, float32."""
        return (self.hdri[start:stop] + self.difference[start:stop]).astype(np.float32, copy=False)


def photographed(scene: SceneData, object_name: str, params: Params, rep: Report, *,
                 mask: UserMask | None = None, geo: Geometry | None = None) -> SeenObject | None:
    """The object as the scene's panorama shows it, segmented around its proxy, with the
    artist's `mask` applied; None when no pixel sees it, or when the preset's band is 0 and
    there is no mask (the proxy's silhouette is filled then). `geo`: the scene's geometry,
    where the caller has built it."""
    index = object_index(scene, object_name)
    if params.segmentation_band <= 0 and mask is None:
        return None
    with rep.stage("segmentation"):
        geo = geo if geo is not None else scene_geometry(scene)
        if not (geo.tri_object == index).any():
            return None
        band = params.segmentation_band
        return seen_object(scene.hdri, geo, index, segment=band > 0, band=max(band, 0.0),
                           max_pixels=params.segmentation_pixels, mask=mask, rep=rep)


def traced_scene(scene: SceneData, object_name: str, planes: list[str] | tuple[str, ...], params: Params,
                 rep: Report, callbacks: RunCallbacks, *, fill: bool = True, seen: SeenObject | None = None,
                 geo: Geometry | None = None) -> tuple[Geometry, Target, Traced]:
    """The geometry (`geo` where the caller has built it), the target and what the pixels
    see. Without `fill` (an insertion has nothing to fill) the pixels around the object are
    relit like the rest; with it, the pixels `seen` shows the object in are filled (default:
    the proxy's silhouette)."""
    geo, target = prepare(scene, object_name, planes, params, rep, geo=geo)
    height, width = scene.hdri.shape[:2]
    with rep.stage("trace"):
        shown = None if seen is None else seen.whole(height, width)
        traced = trace(geo, target, width, height, fill=fill, rep=rep, shown=shown)
    callbacks.check()
    return geo, target, traced


def solve_lighting(hdri: np.ndarray, geo: Geometry, target: Target, traced: Traced, params: Params, rep: Report,
                   callbacks: RunCallbacks, *, seen: SeenObject | None = None) -> Solution:
    """The light before and after the removal at every hit pixel, the room's radiosity read
    from `hdri`; the stages are timed in `rep`."""
    with rep.stage("occluders"):
        occlusion = occluders(geo, target, traced, rep)
    with rep.stage("radiosity"):
        room = solve_room(hdri, geo, target, traced, occlusion, params, rep, callbacks)
    callbacks.check()
    with rep.stage("first_order"):
        first = first_order(room, target, occlusion, params, rep, callbacks)
    with rep.stage("propagation"):
        propagation = propagate_change(first, occlusion, params, rep, callbacks)
    callbacks.check()
    lit = LitRoom(geo=geo, target=target, occlusion=occlusion, room=first.room, db=propagation.db,
                  split=propagation.split)
    with rep.stage("local"):
        local = local_light(lit, traced, params, rep, callbacks)
        lit, local = corrected_near_object(lit, first, traced, traced.panorama_rows(hdri), local, params, rep)
    return Solution(hdri=hdri, params=params, lit=lit, traced=traced, e_h=local.e_h, de_h=local.de_h, seen=seen)


def solve(scene: SceneData, object_name: str, planes: list[str] | tuple[str, ...], params: Params, rep: Report,
          callbacks: RunCallbacks = NO_CALLBACKS, *, fill: bool = True, seen: SeenObject | None = None,
          geo: Geometry | None = None) -> Solution:
    """Every stage of the removal up to the new irradiance of each pixel (`geo`: the scene's
    geometry, where the caller has built it)."""
    geo, target, traced = traced_scene(scene, object_name, planes, params, rep, callbacks, fill=fill, seen=seen,
                                       geo=geo)
    return solve_lighting(scene.hdri, geo, target, traced, params, rep, callbacks, seen=seen)


def finish(solution: Solution, rep: Report, callbacks: RunCallbacks = NO_CALLBACKS) -> RemovalResult:
    """The edited panorama from a solved removal: the ratio form on the pixels that keep their
    surface, texture synthesis where the object was. `callbacks.preview` gets difference
    images as the fill refines."""
    traced = solution.traced
    revealed = traced.behind.revealed
    with rep.stage("compose"):
        d_h = compose(solution, rep)
    d_h = _quiet_working(solution, d_h, rep)

    def difference_image(d_revealed: np.ndarray) -> np.ndarray:
        d = d_h.copy()
        d[revealed] = d_revealed
        return _hit_image(traced, d)

    if len(revealed):
        show = None if callbacks.preview is None else lambda d_revealed: callbacks.show(difference_image(d_revealed))
        with rep.stage("hidden_light"):
            found = working_revealed(solution)
            light = hidden_light(solution, found, callbacks)
        with rep.stage("synthesis"):
            # the seam is the fill's last step: it stays within the stages a removal reports
            change, filled = fill_hidden(solution, found, light, rep, callbacks, show)
            difference = lifted(np.asarray(solution.hdri, np.float32), difference_image(change), filled.lift)
            difference = _seamless(solution, filled_surfaces(solution, found), difference, filled)
    else:
        difference = difference_image(np.zeros((0, 3)))
        rep.skip("synthesis", "the object is not visible from the probe centre: no hidden region to fill"
                 if not traced.hidden_map.any() else "nothing is behind the object to fill")
    rep.info["hidden_region_filled"] = bool(len(revealed) == traced.hidden_map.sum())
    return RemovalResult(difference=difference, hidden_mask=traced.hidden_map, report=rep.as_dict(),
                         hdri=solution.hdri, seen=solution.seen)


def remove(scene: SceneData, object_name: str, *, planes: list[str] | tuple[str, ...] = (),
           params: Params | None = None, callbacks: RunCallbacks = NO_CALLBACKS,
           mask: UserMask | None = None) -> RemovalResult:
    """Remove `object_name`'s shadows and reflected light from the scene's panorama, and fill
    where the photograph shows it (segmented around its proxy, `mask` added or taken away).

    `callbacks.preview(difference)` gets (H, W, 3) float32 difference images before the
    result: the lighting corrected with the hidden region roughly filled, then refined level
    by level."""
    params = params or Params()
    height, width = scene.hdri.shape[:2]
    size = working_size(width, height, max_width=params.working_width)
    full_size = size != (width, height)
    # Above the working width the compose stage gives way to downsample, window, upsample and refine.
    rep = Report(callbacks.progress, stages=STAGES + 3 * full_size)
    rep.info["working_resolution"] = list(size)
    # Built once: the segmentation and the solve trace the same triangles (the working copy
    # has the scene's), and a mesh of 200k triangles takes a fifth of a second to build and
    # as much again to project for its traces (`Geometry.projection`).
    with rep.stage("geometry"):
        geo = scene_geometry(scene)
    seen = photographed(scene, object_name, params, rep, mask=mask, geo=geo)
    callbacks.check()
    if not full_size:
        return finish(solve(scene, object_name, planes, params, rep, callbacks, seen=seen, geo=geo), rep, callbacks)
    with rep.stage("downsample"):
        working = replace(scene, hdri=downsample(scene.hdri, *size))
    solution = solve(working, object_name, planes, params, rep, callbacks, seen=seen, geo=geo)
    if callbacks.preview is not None:
        callbacks.show(_hit_image(solution.traced, compose(solution, Report())))
    return finish_full_size(solution, scene.hdri, rep, callbacks)


def finish_full_size(solution: Solution, hdri: np.ndarray, rep: Report, callbacks: RunCallbacks = NO_CALLBACKS
                     ) -> RemovalResult:
    """The edited full-resolution panorama `hdri` from a removal solved on its working copy."""
    full = full_resolution(solution, hdri, rep, callbacks)
    rep.info["hidden_region_filled"] = full.filled
    return RemovalResult(difference=full.difference, hidden_mask=full.hidden_mask, report=rep.as_dict(), hdri=hdri,
                         seen=solution.seen)


def _quiet_working(solution: Solution, d_h: np.ndarray, rep: Report) -> np.ndarray:
    """The hit pixels' change (N, 3), the relit pixels' noise matched to their surface's
    (`relit_noise`)."""
    traced = solution.traced
    measured = working_measured(solution)
    surface = np.full(traced.height * traced.width, -1, dtype=np.int64)
    surface[traced.hp[measured]] = solution.target.surface_key[traced.tri_h[measured]]
    # The panorama as it is: the pixels that hit nothing have surface -1 and are never read.
    quiet = relit_noise_stage(np.asarray(solution.hdri, np.float32), _hit_image(traced, d_h),
                              surface.reshape(traced.height, traced.width),
                              enabled=solution.params.match_relit_noise, rep=rep)
    return quiet.change.reshape(-1, 3)[traced.hp]


def _seamless(solution: Solution, surface: np.ndarray, difference: np.ndarray, filled: FilledReflectance
              ) -> np.ndarray:
    """The working panorama's `difference` (H, W, 3) with the filled pixels' step against the
    relit photograph around them taken out (`seam`), per `surface` (H, W) as the fill took them
    and as `filled` says it was made."""
    traced = solution.traced
    shape = (traced.height, traced.width)
    at = traced.hp[traced.behind.revealed]

    def image(values: np.ndarray) -> np.ndarray:
        out = np.zeros(traced.height * traced.width, dtype=bool)
        out[at] = values
        return out.reshape(shape)

    return seamless_panorama_change(np.asarray(solution.hdri, np.float32), difference,
                                    image(np.ones(len(at), dtype=bool)), surface,
                                    continued=image(filled.continued), unrepeated=image(filled.unrepeated))


def _hit_image(traced: Traced, rows: np.ndarray) -> np.ndarray:
    """(H, W, 3) float32 image of values (N, 3) of the hit pixels (0 elsewhere)."""
    image = np.zeros((traced.height * traced.width, 3), dtype=np.float32)
    image[traced.hp] = rows
    return image.reshape(traced.height, traced.width, 3)
