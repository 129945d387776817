"""Relocating a real object under the fixed-view constraint (thesis chapter 5).

A relocation is the removal at the old place followed by an insertion at the new one.
Insertion is removal run backwards: removal turns the panorama L1 (object present) into
L0 = L1 E'/E, with E the irradiance with the object and E' without it. Insertion has L0 and
wants L1 = L0 E/E'. Both E come from the radiosity of the room as the panorama shows it, here
the unknown L1, so L1 is a fixed point; the removal's own stages reach it in a few passes
(the first already holds the lamps' shadow exactly, the next ones the light the object
reflects and the bounces it takes away).

The object's appearance is carried along the move (`appearance`). The object hides what is
behind it at the new place because every pixel is traced again with the moved geometry.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..callbacks import NO_CALLBACKS, RunCallbacks
from ..errors import DimredError
from ..light.radiosity import LUMA
from ..quality import Params, rough
from ..removal import RemovalResult, Solution, finish, finish_full_size, solve, solve_lighting, traced_scene
from ..removal.sequence import STAGES, photographed
from ..removal.target import object_index
from ..removal.working import downsample, upsample, working_size
from ..report import Report
from ..scene import SceneData
from ..segmentation.seen import SeenObject
from ..segmentation.user_mask import UserMask
from .appearance import Carried, carry
from .fixedview import Move
from .placement import Placement, place

_RATIO_MAX = 4.0  # an insertion darkens (shadow) or brightens a little (reflected light); beyond this the model failed


@dataclass(frozen=True)
class _Pass:
    """One insertion pass: the panorama with the object at its new place, its report, and
    how many pixels' ratio of irradiances had to be clamped."""

    current: np.ndarray  # (H*W, 3) float64
    report: dict
    wild: int


def relocate(scene: SceneData, object_name: str, move: Move, *, planes: list[str] | tuple[str, ...] = (),
             params: Params | None = None, callbacks: RunCallbacks = NO_CALLBACKS,
             mask: UserMask | None = None) -> RemovalResult:
    """Move `object_name` by `move` in the panorama: removed at its old place (where the
    photograph shows it, `mask` added or taken away), inserted at the new one with its shadow
    and reflected light. `callbacks.preview` gets difference images as for a removal, then
    one after each insertion pass."""
    params = params or Params()
    target = object_index(scene, object_name)
    if not (np.asarray(scene.tri_object) == target).any():
        raise DimredError(f"'{object_name}' has no faces to move")
    height, width = scene.hdri.shape[:2]
    size = working_size(width, height, max_width=params.working_width)
    seen = photographed(scene, object_name, params, Report(), mask=mask)
    if size == (width, height):
        return _relocated(scene, object_name, move, target, planes, params, callbacks, seen).result
    # The moved object's pixels are carried from the working copy, where the move is solved;
    # the removal at its old place runs at full resolution (its fill as sharp as the panorama),
    # and the insertion's change is upsampled onto it.
    small = _relocated(replace(scene, hdri=downsample(scene.hdri, *size)), object_name, move, target, planes, params,
                       callbacks.scaled(0.0, 0.75, ""), seen)
    # The removal's solution on the working copy is the one the relocation already solved.
    full_callbacks = callbacks.scaled(0.75, 1.0, "removal at full resolution: ")
    removal = finish_full_size(small.removal, scene.hdri, Report(full_callbacks.progress, stages=4), full_callbacks)
    upsample(small.inserted, height, width, add_to=removal.difference)
    report = {**small.result.report, "working_resolution": list(size),
              "full_resolution_removal_seconds": removal.report["seconds"]}
    return RemovalResult(difference=removal.difference,
                         hidden_mask=removal.hidden_mask | upsample(small.result.hidden_mask, height, width),
                         report=report, hdri=scene.hdri, seen=seen)


@dataclass(frozen=True)
class _Relocated:
    """A relocation at the panorama's own size, the insertion's share of its change (H, W, 3):
    what the panorama without the object becomes with it at its new place, and the removal's
    solution it started from."""

    result: RemovalResult
    inserted: np.ndarray
    removal: Solution


def _relocated(scene: SceneData, object_name: str, move: Move, target: int, planes: list[str] | tuple[str, ...],
               params: Params, callbacks: RunCallbacks, seen: SeenObject | None) -> _Relocated:
    """The relocation at the panorama's own size, removing the object where `seen` shows it."""
    passes = params.insertion_passes
    if passes < 1:
        raise DimredError(f"insertion_passes must be at least 1, got {passes}")
    placement = place(scene, target, move)
    share = 1.0 / (1 + passes)

    removal_callbacks = callbacks.scaled(0.0, share, "removal: ")
    rep = Report(removal_callbacks.progress, stages=STAGES)
    if seen is not None:
        rep.info["segmentation"] = seen.summary()
    old = solve(scene, object_name, planes, params, rep, removal_callbacks, seen=seen)
    removed = finish(old, rep, removal_callbacks)

    photo = np.asarray(scene.hdri, dtype=np.float64)
    without = np.asarray(removed.edited, dtype=np.float64).reshape(-1, 3)
    moved_scene = replace(scene, triangles=placement.triangles)
    insertion = Report()
    current, carried, steps, wild = without, None, [], 0
    for k in range(passes):
        step_callbacks = callbacks.scaled(share * (k + 1), share * (k + 2), f"insertion {k + 1}/{passes}: ")
        # Only the last pass's lighting is kept; the earlier ones feed it the panorama to read
        # radiosity from, which a draft solve gets nearly as right (0.004 of the error, a third
        # less time, on four scenes).
        step_params = params if k == passes - 1 else rough(params)
        moved = replace(moved_scene, hdri=current.reshape(photo.shape).astype(np.float32))
        step = Report(step_callbacks.progress, stages=STAGES - 2)  # nothing revealed: no hidden light, no synthesis
        geo, moved_target, traced = traced_scene(moved, object_name, planes, step_params, step, step_callbacks,
                                                 fill=False)
        hdri = moved.hdri
        if carried is None:
            # The object's patches send light too: before the first pass reads the panorama as
            # radiosity, the object is put at its new place as photographed.
            carried = carry(old, geo, moved_target, traced, photo, insertion, step_callbacks)
            first_guess = hdri.reshape(-1, 3).copy()
            first_guess[carried.pix] = carried.photographed
            hdri = first_guess.reshape(hdri.shape)
        new = solve_lighting(hdri, geo, moved_target, traced, step_params, step, step_callbacks)
        with insertion.stage("insertion"):
            current, wild = _inserted(new, without, carried, step_callbacks)
        steps.append(step.as_dict())
        if callbacks.preview is not None:
            callbacks.show((current.reshape(photo.shape) - photo).astype(np.float32))
    insertion.guard("insertion_ratio_clamped_pixels", wild)
    difference = (current.reshape(photo.shape) - photo).astype(np.float32)
    hidden = removed.hidden_mask.ravel().copy()
    hidden[carried.pix] = True
    report = _relocation_report(removed.report, steps, insertion.as_dict(), move, placement, carried, passes)
    result = RemovalResult(difference=difference, hidden_mask=hidden.reshape(photo.shape[:2]), report=report,
                           hdri=photo, seen=seen)
    return _Relocated(result, (current - without).reshape(photo.shape).astype(np.float32), old)


def _inserted(new: Solution, without: np.ndarray, carried: Carried, callbacks: RunCallbacks
              ) -> tuple[np.ndarray, int]:
    """(H*W, 3) the panorama without the object (`without`) with the object inserted as the
    pass `new` solved it: every other pixel scaled by E / E', the object's pixels lit anew;
    and how many pixels' ratio had to be clamped."""
    traced = new.traced
    updated = without.copy()
    room = (traced.obj_h != new.target.index) & ~new.room.pixels.emitter_h
    e = new.e_h[room]
    e_without = e + new.de_h[room]
    y_ref = float(np.median(e @ LUMA)) if room.any() else 0.0
    ok = (e_without @ LUMA > 1e-6 * max(y_ref, 1e-30))[:, None] & (e_without > 0.0)
    ratio = np.where(ok, e / np.where(ok, e_without, 1.0), 1.0)
    wild = (ratio > _RATIO_MAX).any(axis=1)
    ratio = np.clip(ratio, 0.0, _RATIO_MAX)
    updated[traced.hp[room]] = without[traced.hp[room]] * ratio
    if len(carried.pix):
        updated[carried.pix] = carried.rho * new.irradiance(carried.tri, carried.bary, callbacks) / np.pi
    return updated, int(wild.sum())


def _relocation_report(removal: dict, steps: list[dict], insertion: dict, move: Move, placement: Placement,
                       carried: Carried, passes: int) -> dict:
    """The removal's report with the insertion's stage times (summed over the passes), the last
    pass's warnings and guards, and what the move did."""
    last = steps[-1]
    report = dict(removal)
    report["seconds"] = {**{f"removal_{k}": v for k, v in removal["seconds"].items() if k != "total"},
                         **{f"insertion_{k}": round(sum(st["seconds"].get(k, 0.0) for st in steps), 4)
                            for k in last["seconds"] if k != "total"},
                         "insertion": insertion["seconds"].get("insertion", 0.0),
                         "total": round(removal["seconds"]["total"] + insertion["seconds"]["total"], 4)}
    report["warnings"] = list(dict.fromkeys(removal["warnings"] + last["warnings"] + insertion["warnings"]))
    report["guards"] = {**removal["guards"], **{f"insertion_{k}": v for k, v in last["guards"].items()},
                        **insertion["guards"]}
    report["relocation"] = {
        "yaw": move.yaw, "distance_scale": move.distance_scale,
        "elevation_change": round(placement.elevation_change, 3), "matrix": placement.matrix.tolist(),
        "support": placement.support, "object_pixels": len(carried.pix), "insertion_passes": passes,
    }
    if abs(placement.elevation_change) > 10.0:
        report["warnings"].append(
            f"the move changes the elevation the object is seen at by {placement.elevation_change:+.1f} degrees: "
            "its sides and top now show at angles the photograph did not see, which the carried appearance cannot show"
        )
    return report
