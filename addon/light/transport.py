"""Light transport from sender patches to receiver points, with and without the removed object.

For receiver x and sender s, T_xs = F_xs * V_xs: the analytic form factor times the fraction of
the sender's sample points visible from x. The same segments are tested against the removed
object O and against every other occluder, which gives both operators at once:

    E(x)  = sum_s T_xs B_s            (the scene as photographed)
    E'(x) = sum_{s not on O} T'_xs B_s  (O gone: its patches send nothing, it blocks nothing)

E' - E is thesis steps 4 and 5 together: light that O blocked comes back, light O reflected
is taken away.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from ..geometry.occluders import Occluders
from ..side_by_side import both
from . import aggregate
from .formfactor import point_to_triangle

_SEGMENTS_PER_CHUNK = 300_000


@dataclass(frozen=True)
class Parts:
    """Senders made of several triangles (clusters of a finely tessellated object): the member
    triangles, their normals and their sender. Form factors add up over the members, near
    ones exactly and far ones by aggregates (`aggregate`)."""

    triangles: np.ndarray  # (T, 3, 3)
    normals: np.ndarray  # (T, 3)
    owner: np.ndarray  # (T,) sender of each member
    far: float = aggregate.FAR  # a group of members is a point patch beyond this many times its radius

    @cached_property
    def clustered(self) -> np.ndarray:
        """The senders that have members."""
        return np.unique(self.owner)

    @cached_property
    def hierarchy(self) -> aggregate.Hierarchy:
        """The hierarchy of the members, their senders numbered as in `clustered`."""
        owner = np.searchsorted(self.clustered, self.owner)
        return aggregate.hierarchy(self.triangles, self.normals, owner, len(self.clustered))


@dataclass(frozen=True)
class Senders:
    """Sender patches: triangles, normals, and the visibility sample points of each.

    Senders are sampled at `len(samples[g])` points each, one count per group g, so the
    important ones can be sampled densely and the rest at their centroid. A sample's weight is
    its share of the patch's light (uniform unless the radiosity varies over the patch, as on a
    patch half under the removed object), and the visible fraction is weighted by it.
    """

    triangles: np.ndarray  # (S, 3, 3)
    normals: np.ndarray  # (S, 3)
    radiosity: np.ndarray  # (S, 3)
    on_removed: np.ndarray  # (S,) bool: the patch belongs to the removed object
    group: np.ndarray  # (S,) which sample group
    slot: np.ndarray  # (S,) row in that group's samples
    samples: list[np.ndarray]  # per group: (n_g, m_g, 3)
    weights: list[np.ndarray]  # per group: (n_g, m_g), each row summing to 1
    parts: Parts | None = None  # senders of several triangles (triangles then holds one member of each)

    def __len__(self) -> int:
        return len(self.triangles)

    def resampled(self, idx: np.ndarray, samples: np.ndarray, weights: np.ndarray) -> Senders:
        """These senders with `idx` sampled at new points (n, m, 3) with light weights (n, m) >= 0."""
        total = weights.sum(axis=1, keepdims=True)
        weights = np.where(total > 0.0, weights / np.where(total > 0.0, total, 1.0), 1.0 / weights.shape[1])
        group, slot = self.group.copy(), self.slot.copy()
        group[idx] = len(self.samples)
        slot[idx] = np.arange(len(idx))
        return replace(self, group=group, slot=slot, samples=[*self.samples, samples],
                       weights=[*self.weights, weights])

    def with_radiosity(self, radiosity: np.ndarray) -> Senders:
        """These senders sending `radiosity` (S, 3)."""
        return replace(self, radiosity=radiosity)

    def subset(self, idx: np.ndarray) -> Senders:
        """The senders `idx` alone (sharing the sample groups)."""
        parts = None
        if self.parts is not None:
            row = np.full(len(self), -1)
            row[idx] = np.arange(len(idx))
            keep = row[self.parts.owner] >= 0
            parts = Parts(self.parts.triangles[keep], self.parts.normals[keep], row[self.parts.owner[keep]],
                          self.parts.far)
        return Senders(self.triangles[idx], self.normals[idx], self.radiosity[idx], self.on_removed[idx],
                       self.group[idx], self.slot[idx], self.samples, self.weights, parts)


def make_senders(triangles: np.ndarray, normals: np.ndarray, radiosity: np.ndarray, on_removed: np.ndarray,
                 sample_sets: list[tuple[np.ndarray, np.ndarray]], parts: Parts | None = None) -> Senders:
    """Senders from (indices, samples) pairs that together cover every sender once."""
    group = np.zeros(len(triangles), dtype=np.int64)
    slot = np.zeros(len(triangles), dtype=np.int64)
    for g, (idx, _) in enumerate(sample_sets):
        group[idx] = g
        slot[idx] = np.arange(len(idx))
    return Senders(triangles, normals, radiosity, on_removed, group, slot, [smp for _, smp in sample_sets],
                   [np.full(smp.shape[:2], 1.0 / smp.shape[1]) for _, smp in sample_sets], parts)


def form_factors(points: np.ndarray, normals: np.ndarray, senders: Senders) -> np.ndarray:
    """(R, S) form factors from receivers (R, 3) with normals (R, 3) to the senders, summed over
    the members of senders made of several triangles."""
    parts = senders.parts
    if parts is None or not len(parts.owner):
        return point_to_triangle(points, normals, senders.triangles, senders.normals)
    single = np.ones(len(senders), dtype=bool)
    single[parts.clustered] = False
    f = np.zeros((len(points), len(senders)))
    # The clusters' aggregates (and on the first call their hierarchy: half a second for a mesh
    # of 200k triangles) on a second thread beside the single senders' exact form factors.
    f[:, single], f[:, parts.clustered] = both(
        lambda: point_to_triangle(points, normals, senders.triangles[single], senders.normals[single]),
        lambda: aggregate.form_factors(np.asarray(points, dtype=np.float64), np.asarray(normals, dtype=np.float64),
                                       parts.hierarchy, far=parts.far))
    return f


def pair_visibility(
    points: np.ndarray, senders: Senders, r: np.ndarray, s: np.ndarray, removed: Occluders | None,
    others: Occluders | None, check: Callable[[], None] | None = None, *, counts: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Visible fractions of sender s[i] from point r[i]: with the removed object, and without it.
    `check()` is called between chunks (it raises to cancel). With `counts` (n,), pair i traces
    only the first counts[i] of its sender's samples in an order that spreads every prefix over
    the sender (`spread_order`), its weights taken over those.

    Only the pairs whose segments can pass the removed object's bounding sphere are traced
    against it (a sender's segments all lie within its samples' sphere of the segment to their
    centre): most of a room's pairs pass nowhere near it, and without other occluders they
    need no ray at all."""
    vis = np.zeros(len(r))
    vis_without = np.zeros(len(r))
    sphere = None if removed is None else _sphere(removed)
    for g, (samples, weights) in enumerate(zip(senders.samples, senders.weights, strict=True)):
        sel = np.flatnonzero(senders.group[s] == g)
        if not len(sel):
            continue
        m = samples.shape[1]
        centre = samples.mean(axis=1)
        reach = np.sqrt(((samples - centre[:, None, :]) ** 2).sum(axis=2).max(axis=1))
        rank = np.argsort(spread_order(samples[0]))
        per = max(1, _SEGMENTS_PER_CHUNK // m)
        for i0 in range(0, len(sel), per):
            if check is not None:
                check()
            k = sel[i0 : i0 + per]
            slot = senders.slot[s[k]]
            use = np.ones((len(k), m), dtype=bool) if counts is None else rank[None, :] < counts[k, None]
            free = np.ones((len(k), m), dtype=bool)  # by the removed object
            free_without = np.ones((len(k), m), dtype=bool)  # by every other occluder
            if sphere is not None:
                near = use & _passes(points[r[k]], centre[slot], reach[slot], *sphere)[:, None]
                free[near] = ~_blocked(removed, points[r[k]], samples[slot], near)
            if others is not None:
                free_without[use] = ~_blocked(others, points[r[k]], samples[slot], use)
            w = weights[slot] * use
            total = 1.0 if counts is None else w.sum(axis=1)
            vis[k] = ((free & free_without) * w).sum(axis=1) / total
            vis_without[k] = (free_without * w).sum(axis=1) / total
    vis_without = np.where(senders.on_removed[s], 0.0, vis_without)
    return vis, vis_without


def spread_order(samples: np.ndarray) -> np.ndarray:
    """(m,) an order of a sender's m sample points (m, 3) whose every prefix spreads over it:
    each next one the farthest from those before (from the one nearest their centre)."""
    gap = np.linalg.norm(samples - samples.mean(axis=0), axis=1)
    order = [int(np.argmin(gap))]
    nearest = np.linalg.norm(samples - samples[order[0]], axis=1)
    for _ in range(len(samples) - 1):
        order.append(int(np.argmax(nearest)))
        nearest = np.minimum(nearest, np.linalg.norm(samples - samples[order[-1]], axis=1))
    return np.array(order)


def _sphere(occluders: Occluders) -> tuple[np.ndarray, float]:
    """Centre (3,) and radius of a sphere holding all the occluders' (grown) boxes."""
    lo, hi = occluders.lo[0].min(axis=1), occluders.hi[0].max(axis=1)
    return 0.5 * (lo + hi), 0.5 * float(np.linalg.norm(hi - lo))


def _passes(points: np.ndarray, ends: np.ndarray, reach: np.ndarray, centre: np.ndarray, radius: float
            ) -> np.ndarray:
    """(n,) whether a segment from points[i] to within reach[i] of ends[i] can meet the sphere."""
    d = ends - points
    t = np.clip(np.einsum("ij,ij->i", centre - points, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0, 1)
    gap = points + t[:, None] * d - centre
    return np.einsum("ij,ij->i", gap, gap) <= (radius + reach) ** 2


def _blocked(occluders: Occluders, points: np.ndarray, samples: np.ndarray, where: np.ndarray) -> np.ndarray:
    """Whether the segments from points (n, 3) to their samples (n, m, 3) are blocked, for
    the entries `where` (n, m) holds."""
    return occluders.blocked(np.repeat(points, where.sum(axis=1), axis=0), samples[where])


def transport(
    points: np.ndarray,
    normals: np.ndarray,
    senders: Senders,
    removed: Occluders | None,
    others: Occluders | None,
    check: Callable[[], None] | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """(T, T') as dense (R, S) float64 matrices for receivers (R, 3) with normals (R, 3)."""
    f = form_factors(points, normals, senders)
    r, s = np.nonzero(f > 0.0)
    vis, vis_without = pair_visibility(points, senders, r, s, removed, others, check)
    t_with = np.zeros_like(f)
    t_without = np.zeros_like(f)
    t_with[r, s] = f[r, s] * vis
    t_without[r, s] = f[r, s] * vis_without
    return t_with, t_without
