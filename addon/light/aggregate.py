"""Form factors to senders made of many small triangles (the clusters of a detailed object), at
a cost that follows how near the receivers are, not how many triangles there are.

A sender's member triangles are grouped by neighbourhood, groups of BRANCH, BRANCH^2, ...
members, each made of BRANCH smaller ones. Seen from beyond FAR times its radius, wholly above
the receiver's horizon and with every member facing the receiver, a sender or a group acts as
a point patch: F = cos_r (V . w) / (pi d^2), V its vector area (the members' areas times their
normals) and w the unit direction from it to the receiver; its relative error is about
(radius / d)^2, some 0.1% on average at FAR = 6 summed over a whole object. Wholly below the
horizon or with every member facing away it sends nothing, exactly. Otherwise it is taken by
its smaller groups, and the smallest member by member with the exact contour formula
(`formfactor`), so a receiver beside the object gets its exact form factor.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.solid import in_frame, principal_frame
from ..side_by_side import each
from .formfactor import paired_point_to_triangle

BRANCH = 4  # groups of BRANCH, BRANCH^2, ... member triangles, each group made of BRANCH smaller ones
FAR = 6.0  # a point patch beyond this many times its radius (the default of `form_factors`)
_RECEIVERS = 256  # receivers taken at once: bounds the (receiver, group) pairs held
_HORIZON = 1e-9  # height over a receiver's tangent plane below which nothing is received (as `formfactor`)


@dataclass(frozen=True)
class Aggregates:
    """Bounds and light-exchange summary of sets of triangles, one row a set."""

    centre: np.ndarray  # (n, 3) area-weighted centroid
    radius: np.ndarray  # (n,) of the ball around the centre holding every vertex
    box_centre: np.ndarray  # (n, 3) centre of the bounding box in the hierarchy's frame
    half: np.ndarray  # (n, 3) half its extent
    vector: np.ndarray  # (n, 3) vector area: sum of area times unit normal
    axis: np.ndarray  # (n, 3) unit mean normal (zero when the normals cancel)
    spread: np.ndarray  # (n,) largest distance of a member's normal from the axis
    offsets: np.ndarray  # (n, 2) least and greatest axis . vertex (a flat run's plane, twice)


@dataclass(frozen=True)
class Hierarchy:
    """Senders made of several triangles, their groups and members, for `form_factors`:
    levels[0] are the senders, each level's rows are cut into the next one's, the last
    level's into members."""

    triangles: np.ndarray  # (T, 3, 3) the members, by sender, then in space-filling order
    normals: np.ndarray  # (T, 3) their unit normals (the side they send to)
    frame: np.ndarray  # (3, 3) rows: the axes the boxes are taken along (`solid.principal_frame`)
    levels: tuple[Aggregates, ...]
    children: tuple[np.ndarray, ...]  # per level (n + 1,): first row of each in the next level (or member)
    sender: tuple[np.ndarray, ...]  # per level (n,): the sender each row belongs to
    owner: np.ndarray  # (T,) the sender of each member


def hierarchy(triangles: np.ndarray, normals: np.ndarray, owner: np.ndarray, count: int) -> Hierarchy:
    """The hierarchy of `count` senders made of triangles (T, 3, 3) with unit normals (T, 3)
    sending to that side, triangle t belonging to sender owner[t] (every sender at least one)."""
    order = np.lexsort((_morton(triangles.mean(axis=1)), owner))
    triangles, normals, owner = triangles[order], normals[order], owner[order]
    first = np.searchsorted(owner, np.arange(count + 1))
    rank = np.arange(len(owner)) - first[owner]
    largest = int(np.diff(first).max())
    # Members of a row of level L are those of one sender with the same rank // size[L].
    sizes = [largest] + [BRANCH**e for e in range(int(np.log(max(largest - 1, 1)) / np.log(BRANCH)), 0, -1)]
    row_of = []  # (T,) each member's row, per level
    for size in sizes:
        per_sender = -(-np.diff(first) // size)
        row_of.append(np.concatenate([[0], np.cumsum(per_sender)])[owner] + rank // size)
    frame = principal_frame(triangles)
    members = _Members.of(triangles, normals, in_frame(triangles, frame))
    starts_of = [np.searchsorted(rows, np.arange(rows[-1] + 2)) for rows in row_of]
    levels = each(members.aggregates, starts_of)  # the levels side by side (a mesh of 200k: 0.29 -> 0.17 s)
    children, sender = [], []
    for level, starts in enumerate(starts_of):
        sender.append(owner[starts[:-1]])
        below = row_of[level + 1] if level + 1 < len(row_of) else np.arange(len(owner))
        children.append(np.append(below[starts[:-1]], below[-1] + 1))
    return Hierarchy(triangles, normals, frame, tuple(levels), tuple(children), tuple(sender), owner)


@dataclass(frozen=True)
class _Members:
    """What the aggregates of runs of member triangles are made of, computed once."""

    triangles: np.ndarray  # (T, 3, 3)
    normals: np.ndarray  # (T, 3)
    area: np.ndarray  # (T,)
    moment: np.ndarray  # (T, 3) area times centroid
    vector: np.ndarray  # (T, 3) area times normal
    lo: np.ndarray  # (T, 3) bounding box in the hierarchy's frame
    hi: np.ndarray

    @classmethod
    def of(cls, triangles: np.ndarray, normals: np.ndarray, framed: np.ndarray) -> _Members:
        area = 0.5 * np.linalg.norm(np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0]),
                                    axis=1)
        lo = np.minimum(np.minimum(framed[:, 0], framed[:, 1]), framed[:, 2])
        hi = np.maximum(np.maximum(framed[:, 0], framed[:, 1]), framed[:, 2])
        return cls(triangles, normals, area, area[:, None] * triangles.mean(axis=1), area[:, None] * normals, lo, hi)

    def aggregates(self, starts: np.ndarray) -> Aggregates:
        """The aggregates of the contiguous runs of members starting at starts[:-1]."""
        first = starts[:-1]
        run = np.repeat(np.arange(len(first)), np.diff(starts))
        total = np.add.reduceat(self.area, first)
        centre = np.add.reduceat(self.moment, first) / np.maximum(total, 1e-300)[:, None]
        vector = np.add.reduceat(self.vector, first)
        length = np.sqrt(np.einsum("ij,ij->i", vector, vector))
        has_axis = length > 1e-12 * total
        axis = np.where(has_axis[:, None], vector / np.maximum(length, 1e-300)[:, None], 0.0)
        # Each member's run's centre and axis gathered once; minima and maxima of three columns
        # taken pairwise (a reduction over an axis of 3 is numpy's slow path): a mesh of 200k
        # triangles builds its seven levels in half the time.
        centres, axes = centre[run], axis[run]
        reach2, least, most = None, None, None
        for k in range(3):
            gap = self.triangles[:, k] - centres
            dist2 = np.einsum("ij,ij->i", gap, gap)
            height = np.einsum("ij,ij->i", self.triangles[:, k], axes)
            if reach2 is None:
                reach2, least, most = dist2, height, height.copy()
            else:
                np.maximum(reach2, dist2, out=reach2)
                np.minimum(least, height, out=least)
                np.maximum(most, height, out=most)
        turn = self.normals - axes
        # A run whose normals cancel has no axis: the spread of 2 keeps it from ever counting as a point patch.
        spread = np.where(has_axis, np.sqrt(np.maximum.reduceat(np.einsum("ij,ij->i", turn, turn), first)), 2.0)
        offsets = np.stack([np.minimum.reduceat(least, first), np.maximum.reduceat(most, first)], axis=1)
        lo, hi = np.minimum.reduceat(self.lo, first), np.maximum.reduceat(self.hi, first)
        return Aggregates(centre, np.sqrt(np.maximum.reduceat(reach2, first)), 0.5 * (lo + hi), 0.5 * (hi - lo),
                          vector, axis, spread, offsets)


def _morton(points: np.ndarray) -> np.ndarray:
    """(N,) Morton codes of points quantised to 10 bits per axis over their bounding box."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    q = ((points - lo) / np.maximum(hi - lo, 1e-300) * 1023).astype(np.int64)
    code = np.zeros(len(points), dtype=np.int64)
    for bit in range(10):
        for axis in range(3):
            code |= ((q[:, axis] >> bit) & 1) << (3 * bit + axis)
    return code


def form_factors(points: np.ndarray, normals: np.ndarray, h: Hierarchy, *, far: float = FAR) -> np.ndarray:
    """(R, C) form factors from receivers (R, 3) with unit normals (R, 3) to the senders, a
    group taken as a point patch beyond `far` times its radius (relative error about
    (radius / distance)^2: over a box's receivers 0.2 % on average at 6, 0.5 % at 3)."""
    count = len(h.levels[0].radius)
    out = np.zeros((len(points), count))
    for r0 in range(0, len(points), _RECEIVERS):
        x, n = points[r0 : r0 + _RECEIVERS], normals[r0 : r0 + _RECEIVERS]
        xf, nf = in_frame(x, h.frame), in_frame(n, h.frame)
        f = np.zeros(len(x) * count)
        rows, items = np.repeat(np.arange(len(x)), count), np.tile(np.arange(count), len(x))
        for agg, children, sender in zip(h.levels, h.children, h.sender, strict=True):
            value, near = _point_patches(x[rows], n[rows], xf[rows], nf[rows], agg, items, far)
            f += np.bincount(rows * count + sender[items], value, minlength=f.size)
            rows, items = _expand(rows[near], items[near], children)
        exact = paired_point_to_triangle(x[rows], n[rows], h.triangles[items], h.normals[items])
        f += np.bincount(rows * count + h.owner[items], exact, minlength=f.size)
        out[r0 : r0 + len(x)] = f.reshape(len(x), count)
    return out


def _point_patches(x: np.ndarray, n: np.ndarray, xf: np.ndarray, nf: np.ndarray, agg: Aggregates, k: np.ndarray,
                   far: float) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of receivers x (P, 3) with unit normals n (P, 3) (xf, nf: in the hierarchy's
    frame) and aggregates k (P,): the form factor (P,) where the aggregate is a point patch
    for the receiver (0 where it sends nothing) and (P,) where it is neither, so it must be
    taken by its parts.

    The members' heights over the receiver's tangent plane are bounded by the aggregate's
    ball and box, the receiver's heights in front of the members' planes by their offsets
    along the axis and the spread of their normals (exact for a flat run)."""
    v = x - agg.centre[k]
    d2 = np.einsum("ij,ij->i", v, v)
    d = np.sqrt(d2)
    radius = agg.radius[k]
    over_centre = -np.einsum("ij,ij->i", n, v)
    over_box = np.einsum("ij,ij->i", nf, agg.box_centre[k] - xf)
    box_reach = np.einsum("ij,ij->i", np.abs(nf), agg.half[k])
    highest = np.minimum(over_centre + radius, over_box + box_reach)
    lowest = np.maximum(over_centre - radius, over_box - box_reach)
    ahead = np.einsum("ij,ij->i", agg.axis[k], x)
    turn = agg.spread[k] * (d + radius)
    nearest = ahead - agg.offsets[k, 1] - turn
    farthest = ahead - agg.offsets[k, 0] + turn
    # The contour formula clips at _HORIZON: members no higher send nothing there either, and
    # one touching the horizon loses only a sliver to it.
    nothing = (highest <= _HORIZON) | (farthest <= 0.0)
    point = (lowest >= -_HORIZON) & (nearest > 0.0) & (d > far * radius)
    flux = over_centre * np.einsum("ij,ij->i", agg.vector[k], v)
    value = np.divide(flux, np.pi * d2 * d2, out=np.zeros(len(v)), where=point)
    return value, ~(nothing | point)


def _expand(rows: np.ndarray, items: np.ndarray, starts: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row, child) pairs for every child starts[item] .. starts[item + 1] - 1 of each (row, item)."""
    count = starts[items + 1] - starts[items]
    first = np.repeat(starts[items] - (np.cumsum(count) - count), count)
    return np.repeat(rows, count), first + np.arange(int(count.sum()))
