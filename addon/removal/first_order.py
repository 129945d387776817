"""The first-order change of irradiance of every patch once the object is gone (light it
blocked comes back, light it reflected goes), sampled within the patches near the object."""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry.patches import triangle_samples
from ..light.planner import neighbourhood
from ..light.radiosity import LUMA, RHO_MAX
from ..light.split import Split
from ..quality import Params
from ..report import Report
from .occlusion import Occlusion
from .room import Room
from .significance import significant
from .target import Target

# A group of sampled patches: their indices (n,), the level k, and the radiosity as
# photographed and its first change at the centroids of their k^2 sub-triangles (each (n, k^2, 3)).
Group = tuple[np.ndarray, int, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class FirstOrder:
    """The room with its patches near the object re-measured and resampled, the first-order
    change dE (P, 3) of each patch's mean irradiance, and the patches split because their
    light varies within them."""

    room: Room
    de: np.ndarray
    split: Split
    refined: np.ndarray  # (n,) the patches near the object, sampled within


@dataclass
class _Samples:
    """k^2 points on each of n patches and what is known there: scratch of the first order,
    whose transport it completes in place (never part of a stage's result)."""

    points: np.ndarray  # (n*k^2, 3)
    normals: np.ndarray  # (n*k^2, 3)
    t_with: np.ndarray  # (n*k^2, P) transport from the patches with the object
    t_without: np.ndarray  # (n*k^2, P) ... without it
    past_object: np.ndarray  # (n, k^2, 1) the probe sees the point past the object
    seen: np.ndarray  # (n, k^2, 1) the probe sees the point at all


def first_order(room: Room, target: Target, occlusion: Occlusion, params: Params, rep: Report,
                callbacks: RunCallbacks) -> FirstOrder:
    """(P, 3) first-order change of irradiance, averaged over each patch, and the split of
    those whose light varies within them (see `_split`).

    Patches near the object are sampled at k^2 points, and the samples the probe cannot see
    correct what the pixels alone got wrong for a patch partly under or behind the object:
    its reflectance is B over the E of the seen samples (B comes from visible pixels, and E
    ~ 0 under the object), and its radiosity as a sender covers the unseen part too (dark
    under the object: with B of the lit part there, taking the object away would seem to
    reveal light that was never there, on top of the light the revealed part really gets)."""
    b = room.senders.radiosity
    ptris = room.patches.triangles
    centre = ptris.mean(axis=1)
    radius = np.linalg.norm(ptris - centre[:, None, :], axis=2).max(axis=1)
    imp = np.flatnonzero(room.important)
    e = room.patch_mean(room.t_with @ b)
    near = significant(room.senders, imp, centre, e, target, params, margin=radius).any(axis=1)
    near |= neighbourhood(centre, target.centre, target.radius + radius, reach=params.reach)
    refine = np.flatnonzero(near & ~room.senders.on_removed & ~room.emitter)
    rep.info["refined_patches"] = len(refine)
    if not len(refine):
        de = room.patch_mean((room.t_without - room.t_with) @ b)
        return FirstOrder(room, de, _split(room, de, [], params), refine)
    k = params.patch_samples
    sampled = _sample(room, refine, k, occlusion, callbacks)
    # The samples are this function's own: their transport is completed in place below.
    t_samples, t_samples_without = sampled.t_with, sampled.t_without
    n, k2 = sampled.seen.shape[:2]
    e_samples = (t_samples @ b).reshape(n, k2, 3)
    n_seen = sampled.seen.sum(axis=1)
    e_seen = (e_samples * sampled.seen).sum(axis=1) / np.maximum(n_seen, 1)
    remeasure = room.visible[refine] & (n_seen[:, 0] > 0) & ((e_seen @ LUMA) > 0.0)
    rho = room.rho.copy()
    idx = refine[remeasure]
    rho[idx] = np.clip(b[idx] / np.maximum(e_seen[remeasure], 1e-30), 0.0, RHO_MAX)
    room = replace(room, rho=rho)

    # Only the object's cover differs between T and T'; a centroid under the object hides
    # the patch from receivers that see most of it.
    under = ~sampled.past_object.all(axis=(1, 2)) | ~occlusion.seen(centre[refine])[0]
    partial = refine[under]
    groups: list[Group] = []
    if len(partial):
        room, b_sub, de_sub = _resample(room, partial, 2 * k, occlusion, rep, callbacks)
        groups.append((partial, 2 * k, b_sub, de_sub))
        t_samples[:, partial], t_samples_without[:, partial] = occlusion.transport(
            sampled.points, sampled.normals, room.senders.subset(partial), callbacks)
    b = room.senders.radiosity
    de_samples = ((t_samples_without - t_samples) @ b).reshape(n, k2, 3)
    whole = refine[~under]
    groups.append((whole, k, np.broadcast_to(b[whole, None, :], (len(whole), k2, 3)), de_samples[~under]))
    de = room.patch_mean((room.t_without - room.t_with) @ b)
    for idx, _, _, de_g in groups:
        de[idx] = de_g.mean(axis=1)
    return FirstOrder(room, de, _split(room, de, groups, params), refine)


def _sample(room: Room, idx: np.ndarray, k: int, occlusion: Occlusion, callbacks: RunCallbacks) -> _Samples:
    """k^2 points on each patch idx, their transport with and without the object, and whether
    the probe sees them."""
    points = triangle_samples(room.patches.triangles[idx], k).reshape(-1, 3)
    normals = np.repeat(room.senders.normals[idx], k * k, axis=0)
    t_with, t_without = occlusion.transport(points, normals, room.senders, callbacks)
    past_object, seen = (v.reshape(len(idx), k * k, 1) for v in occlusion.seen(points))
    return _Samples(points, normals, t_with, t_without, past_object, seen)


def _resample(room: Room, idx: np.ndarray, k: int, occlusion: Occlusion, rep: Report, callbacks: RunCallbacks
              ) -> tuple[Room, np.ndarray, np.ndarray]:
    """The room with patches idx as senders sampled at k^2 points weighted by their light, dark
    where the probe cannot see and the estimate says so; B and the first-order change of E at
    those points (each (n, k^2, 3))."""
    b = room.senders.radiosity.copy()
    sampled = _sample(room, idx, k, occlusion, callbacks)
    t_samples, t_samples_without = sampled.t_with, sampled.t_without
    e_samples = (t_samples @ b).reshape(len(idx), k * k, 3)
    b_samples = np.where(sampled.seen, b[idx, None, :], room.rho[idx, None, :] * e_samples)
    b[idx] = b_samples.mean(axis=1)
    points = sampled.points.reshape(len(idx), k * k, 3)
    senders = room.senders.with_radiosity(b).resampled(idx, points, b_samples @ LUMA)
    sub = senders.subset(idx)
    t_with, t_without = room.t_with.copy(), room.t_without.copy()
    t_with[:, idx], t_without[:, idx] = occlusion.transport(room.receivers.points, room.receivers.normals, sub,
                                                            callbacks)
    t_samples[:, idx], t_samples_without[:, idx] = occlusion.transport(sampled.points, sampled.normals, sub, callbacks)
    rep.info["resampled_patches"] = len(idx)
    room = replace(room, senders=senders, t_with=t_with, t_without=t_without)
    return room, b_samples, ((t_samples_without - t_samples) @ b).reshape(len(idx), k * k, 3)


def _split(room: Room, de: np.ndarray, groups: list[Group], params: Params) -> Split:
    """The sampled patches whose light varies enough to matter: what the means of B and of its
    first change miss over the patch holds at least `bounce_tolerance` of the whole first
    change (the share where the propagation stops). A few patches at the object's contact and
    shadow edges qualify; important senders keep their exact per-pixel treatment."""
    db1 = room.rho * de
    db1[room.senders.on_removed | room.emitter] = 0.0
    first = float((np.abs(db1) @ LUMA * room.areas).sum())
    b = room.senders.radiosity
    keep = []
    for idx, k, b_g, de_g in groups:
        db_g = room.rho[idx, None, :] * de_g
        missed = (np.abs(b_g - b[idx, None, :]) + np.abs(db_g - db1[idx, None, :])) @ LUMA
        sel = (missed.mean(axis=1) * room.areas[idx] >= params.bounce_tolerance * first) & ~room.important[idx]
        keep.append((idx[sel], k, b_g[sel], db_g[sel]))
    patches = room.patches
    return Split.of(patches.triangles, room.senders.normals, patches.areas, keep)
