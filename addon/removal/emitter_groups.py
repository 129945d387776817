"""Important senders that are one emitter: a window or a lit wall split into many patches.

Traced pair by pair, a window of twenty patches costs twenty senders' rays at every pixel its
shadow reaches, though the pixel's light depends on the window as a whole. The patches of one
emitter (important senders side by side on one plane) share a budget of rays at each pixel,
GROUP_SAMPLES times one sender's, given out in proportion to what each patch sends there: a
patch that lights the pixel much gets its full sampling, one that lights it little a ray or
two. A lamp of one or two patches keeps every sample.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..light.transport import Senders

GROUP_SAMPLES = 2  # an emitter's rays at a pixel, in one of its patches' samples
_SAME_PLANE_COS = 0.999
_TOUCH = 1e-6  # patches whose vertices come this close (relative to the room) are side by side


@dataclass(frozen=True)
class EmitterGroups:
    """The emitter (S,) of each sender, -1 for those not important, and the patches (G,) each
    of the G emitters holds."""

    of: np.ndarray
    sizes: np.ndarray


def emitter_groups(senders: Senders, imp: np.ndarray) -> EmitterGroups:
    """The important senders `imp` joined into emitters: side by side (sharing a vertex) on one
    plane, and so on transitively."""
    of = np.full(len(senders), -1)
    if not len(imp):
        return EmitterGroups(of, np.zeros(0, dtype=np.int64))
    tris, normals = senders.triangles[imp], senders.normals[imp]
    scale = float(np.ptp(senders.triangles.reshape(-1, 3), axis=0).max()) or 1.0
    vertices = tris.reshape(len(imp), 1, 3, 1, 3) - tris.reshape(1, len(imp), 1, 3, 3)
    touch = (np.linalg.norm(vertices, axis=-1) <= _TOUCH * scale).any(axis=(2, 3))
    offset = np.einsum("ic,ic->i", normals, tris[:, 0])
    coplanar = ((normals @ normals.T) >= _SAME_PLANE_COS) & (
        np.abs(np.einsum("ic,jc->ij", normals, tris[:, 0]) - offset[:, None]) <= _TOUCH * scale)
    joined = touch & coplanar
    label = np.arange(len(imp))
    while True:  # each round takes the least label among neighbours: at most len(imp) rounds
        least = np.where(joined, label[None, :], len(imp)).min(axis=1)
        new = np.minimum(label, least)
        if (new == label).all():
            break
        label = new
    _, group = np.unique(label, return_inverse=True)
    of[imp] = group
    return EmitterGroups(of, np.bincount(group))


def sample_counts(groups: EmitterGroups, pix: np.ndarray, s: np.ndarray, light: np.ndarray, samples: np.ndarray
                  ) -> np.ndarray:
    """(n,) how many of its `samples` (n,) points the pair (pixel pix, important sender s)
    traces: its share of what its emitter sends the pixel (`light` (n,) >= 0, the pair's)
    times GROUP_SAMPLES emitters' worth, at least one, at most all."""
    key = pix * len(groups.sizes) + groups.of[s]
    _, pair_key = np.unique(key, return_inverse=True)
    total = np.bincount(pair_key, light)[pair_key]
    share = np.divide(light, total, out=np.ones_like(light), where=total > 0)
    return np.clip(np.ceil(GROUP_SAMPLES * samples * share), 1, samples).astype(np.int64)
