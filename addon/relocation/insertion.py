"""Relocating a real object under the fixed-view constraint (DESIGN 6, thesis chapter 5).

A relocation is the removal at the old place followed by an insertion at the new one.
Insertion is removal run backwards: removal turns the panorama L1 (object present) into
L0 = L1 E'/E, with E the irradiance with the object and E' without it. Insertion has L0 and
wants L1 = L0 E/E'. Both E come from the radiosity of the room as the panorama shows it, here
the unknown L1, so L1 is a fixed point; the removal's own solver reaches it in a few passes
(the first already holds the lamps' shadow exactly, the next ones the light the object
reflects and the bounces it takes away).

The object's appearance is carried along the move. Each of its points at the new place takes
the photograph's radiance at its old place (where the probe saw it there), divided by the
irradiance there, which removes the shadows other things cast on it as far as the model holds
(thesis 5.2), and lit with the irradiance at the new place. The object hides what is behind it
at the new place because every pixel is traced again with the moved geometry.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import numpy as np

from . import fixedview
from ..geometry import latlong
from ..errors import DimredError
from .fixedview import Move
from .placement import place
from ..geometry.mesh import Geometry
from ..quality import Params, rough
from ..light.radiosity import LUMA, RHO_MAX
from ..removal.stages import RemovalResult, Solution, _Removal, finish, solve
from ..report import Report
from ..scene import SceneData

_RATIO_MAX = 4.0  # an insertion darkens (shadow) or brightens a little (reflected light); beyond this the model failed
_SEEN_DEPTH = 0.02  # a photographed pixel shows a point of the object if its depth agrees to this share


def _map_rows(old: Geometry, new: Geometry, tri_new: np.ndarray) -> np.ndarray:
    """Triangle indices of the old geometry for triangles of the new one (the same rows of the
    scene's triangle list; -1 where the old geometry dropped the row)."""
    index = np.full(int(max(old.source.max(), new.source.max())) + 1, -1, dtype=np.int64)
    index[old.source] = np.arange(len(old.source))
    return index[new.source[tri_new]]


def _photographed(old: Solution, photo: np.ndarray, tri: np.ndarray, bary: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) the photograph's radiance at points of the object given in the old geometry, and
    (N,) whether the probe saw them there (bilinear over the neighbouring pixels that show the
    object at the point's depth)."""
    job = old.job
    tris = job.geo.triangles[tri]
    points = tris[:, 0] + bary[:, :1] * (tris[:, 1] - tris[:, 0]) + bary[:, 1:] * (tris[:, 2] - tris[:, 0])
    depth = np.linalg.norm(points, axis=1)
    u, v = latlong.direction_to_uv(points / np.maximum(depth, 1e-300)[:, None])
    x = u * job.width - 0.5
    y = (1.0 - v) * job.height - 0.5
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    on_object = (job.hits.tri >= 0) & (job.geo.tri_object[np.maximum(job.hits.tri, 0)] == job.target)
    total = np.zeros((len(points), 3))
    weight = np.zeros(len(points))
    for dy in (0, 1):
        for dx in (0, 1):
            yy = np.clip(y0 + dy, 0, job.height - 1)
            xx = (x0 + dx) % job.width
            w = (1.0 - np.abs(x - (x0 + dx))) * (1.0 - np.abs(y - (y0 + dy)))
            ok = on_object[yy, xx] & (np.abs(job.hits.distance[yy, xx] - depth) <= _SEEN_DEPTH * depth)
            w = np.where(ok, w, 0.0)
            total += w[:, None] * photo[yy, xx]
            weight += w
    seen = weight > 0.25
    return np.where(seen[:, None], total / np.maximum(weight, 1e-300)[:, None], 0.0), seen


@dataclass
class _Carried:
    """The object's pixels at the new place and what the old place tells about them."""

    pix: np.ndarray  # (N,) flat pixel indices showing the object at the new place
    tri: np.ndarray  # (N,) its triangles there (new geometry)
    bary: np.ndarray  # (N, 2)
    rho: np.ndarray  # (N, 3) its reflectance, from the photograph and the irradiance at the old place
    photographed: np.ndarray  # (N, 3) the photograph's radiance there (the first guess, before relighting)


def _carry(old: Solution, job: _Removal, photo: np.ndarray, rep: Report) -> _Carried:
    """Map the object's pixels at the new place (`job`, traced) to its old place: radiance,
    reflectance, and a guard count of the points the photograph does not show."""
    on = job.obj_h == job.target
    pix = job.hp[on]
    tri_new = job.tri_h[on]
    bary = job.hits.bary.reshape(-1, 2)[pix]
    if not len(pix):
        rep.warn(f"at the new place '{job.geo.object_names[job.target]}' is hidden from the probe: only its shadow "
                 "and reflected light change the panorama")
        return _Carried(pix, tri_new, bary, np.zeros((0, 3)), np.zeros((0, 3)))
    tri_old = _map_rows(old.job.geo, job.geo, tri_new)
    known = tri_old >= 0
    radiance = np.zeros((len(pix), 3))
    seen = np.zeros(len(pix), dtype=bool)
    e_old = np.zeros((len(pix), 3))
    if known.any():
        radiance[known], seen[known] = _photographed(old, photo, tri_old[known], bary[known])
        e_old[known] = old.irradiance(tri_old[known], bary[known])
    y_old = e_old @ LUMA
    lit = seen & (y_old > 1e-3 * max(float(np.median(y_old[seen])) if seen.any() else 0.0, 1e-30))
    implied = np.pi * radiance[lit] / np.maximum(e_old[lit], 1e-30)
    rep.guard("object_reflectance_clamped_pixels", int((implied > RHO_MAX).any(axis=1).sum()))
    rho = np.zeros((len(pix), 3))
    rho[lit] = np.clip(implied, 0.0, RHO_MAX)
    if lit.any():
        rho[~lit] = np.median(rho[lit], axis=0)
        radiance[~lit] = np.median(radiance[lit], axis=0)
    else:
        rho[:] = np.median(old.room.rho[old.room.senders.on_removed], axis=0)
        radiance[:] = rho * np.median(e_old, axis=0) / np.pi
        rep.warn("the probe did not see the object well enough to take its appearance from the panorama: "
                 "it is shown with its estimated mean reflectance")
    unseen = int((~lit).sum())
    if unseen:
        # Points the photograph does not show (a nearer object is seen more from above) or
        # shows too dark to measure (its own deep shadow) take the object's median.
        rep.guard("object_pixels_without_photograph", unseen)
    return _Carried(pix, tri_new, bary, rho, radiance)


def _scaled(progress: Callable[[str, float], None] | None, lo: float, hi: float, prefix: str):
    if progress is None:
        return None
    return lambda stage, fraction: progress(f"{prefix}{stage}", lo + (hi - lo) * fraction)


def relocate(
    scene: SceneData,
    object_name: str,
    move: Move,
    planes: list[str] | tuple[str, ...] = (),
    params: Params | None = None,
    progress: Callable[[str, float], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    preview: Callable[[np.ndarray], None] | None = None,
) -> RemovalResult:
    """Move `object_name` by `move` in the panorama: removed at its old place, inserted at the
    new one with its shadow and reflected light. `preview` gets difference images as for a
    removal, then one after each insertion pass."""
    params = params or Params()
    if object_name not in scene.object_names:
        raise DimredError(f"no mesh object named '{object_name}' among the scene's proxy geometry")
    target = scene.object_names.index(object_name)
    if not (np.asarray(scene.tri_object) == target).any():
        raise DimredError(f"'{object_name}' has no faces to move")
    passes = params.insertion_passes
    if passes < 1:
        raise DimredError(f"insertion_passes must be at least 1, got {passes}")
    placement = place(scene, target, move)
    share = 1.0 / (1 + passes)

    rep = Report(_scaled(progress, 0.0, share, "removal: "), stages=8)
    old = solve(scene, object_name, planes, params, rep, cancel)
    removed = finish(old, rep, preview)
    report = removed.report

    photo = np.asarray(scene.hdri, dtype=np.float64)
    without = np.asarray(removed.edited, dtype=np.float64).reshape(-1, 3)
    current = without.copy()
    moved_scene = replace(scene, triangles=placement.triangles)
    insertion = Report()
    carried: list[_Carried] = []
    steps: list[dict] = []

    def first_guess(job) -> None:
        # The object's patches send light too: before the first pass reads the panorama as
        # radiosity, the object is put at its new place as photographed.
        carried.append(_carry(old, job, photo, insertion))
        image = job.hdri.reshape(-1, 3).copy()
        image[carried[0].pix] = carried[0].photographed
        job.hdri = image.reshape(job.hdri.shape)

    for k in range(passes):
        step = Report(_scaled(progress, share * (k + 1), share * (k + 2), f"insertion {k + 1}/{passes}: "), stages=7)
        image = current.reshape(photo.shape).astype(np.float32)
        # Only the last pass's lighting is kept; the earlier ones feed it the panorama to read
        # radiosity from, which a draft solve gets nearly as right (0.004 of the error, a third
        # less time, on four scenes).
        new = solve(replace(moved_scene, hdri=image), object_name, planes,
                    params if k == passes - 1 else rough(params), step, cancel,
                    traced=None if carried else first_guess, fill=False)
        with insertion.stage("insertion"):
            updated = without.copy()
            job = new.job
            room = (job.obj_h != job.target) & ~job.emitter_h
            e = new.e_pix[room]
            e_without = e + new.de_pix[room]
            y_ref = float(np.median(e @ LUMA)) if room.any() else 0.0
            ok = (e_without @ LUMA > 1e-6 * max(y_ref, 1e-30))[:, None] & (e_without > 0.0)
            ratio = np.where(ok, e / np.where(ok, e_without, 1.0), 1.0)
            wild = (ratio > _RATIO_MAX).any(axis=1)
            ratio = np.clip(ratio, 0.0, _RATIO_MAX)
            updated[job.hp[room]] = without[job.hp[room]] * ratio
            obj = carried[0]
            if len(obj.pix):
                updated[obj.pix] = obj.rho * new.irradiance(obj.tri, obj.bary) / np.pi
            current = updated
        steps.append(step.as_dict())
        if preview is not None:
            preview((current.reshape(photo.shape) - photo).astype(np.float32))
    last = steps[-1]
    insertion.guard("insertion_ratio_clamped_pixels", int(wild.sum()))
    difference = (current.reshape(photo.shape) - photo).astype(np.float32)
    hidden = removed.hidden_mask.ravel().copy()
    hidden[carried[0].pix] = True
    done = insertion.as_dict()
    report["seconds"] = {**{f"removal_{k}": v for k, v in report["seconds"].items() if k != "total"},
                         **{f"insertion_{k}": round(sum(st["seconds"].get(k, 0.0) for st in steps), 4)
                            for k in last["seconds"] if k != "total"},
                         "insertion": done["seconds"].get("insertion", 0.0),
                         "total": round(report["seconds"]["total"] + done["seconds"]["total"], 4)}
    report["warnings"] = list(dict.fromkeys(report["warnings"] + last["warnings"] + done["warnings"]))
    report["guards"].update({f"insertion_{k}": v for k, v in last["guards"].items()})
    report["guards"].update(done["guards"])
    report["relocation"] = dict(
        yaw=move.yaw, distance_scale=move.distance_scale, elevation_change=round(placement.elevation_change, 3),
        matrix=placement.matrix.tolist(), support=placement.support, object_pixels=int(len(carried[0].pix)),
        insertion_passes=passes,
    )
    if abs(placement.elevation_change) > 10.0:
        report["warnings"].append(
            f"the move changes the elevation the object is seen at by {placement.elevation_change:+.1f} degrees: "
            "its sides and top now show at angles the photograph did not see, which the carried appearance cannot show"
        )
    return RemovalResult(difference=difference, edited=(photo + difference).astype(np.float32),
                         hidden_mask=hidden.reshape(photo.shape[:2]), report=report)
