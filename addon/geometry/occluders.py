"""Which segments p0 -> p1 the occluding objects block, exactly and for many segments at once.

Each object is tested in its own frame (`solid.principal_frame`): a segment that misses its
bounding box there is free of it; one that enters a region certainly inside its closed
surface from outside the box is blocked (`solid.inner_boxes`); the rest descend its
hierarchy (`bvh`) down to exact triangle tests. So the cost follows how many segments pass
near the object and how close, not how many triangles it has.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..side_by_side import both
from . import bvh, solid

_SEG_CHUNK = 200_000
_END_GAP = 30.0  # segment ends stop this many tolerances short of the surfaces they join
_INV32 = np.float32(1e30)  # 1 / d held to this in float32 (bvh.inverse gives up to 1e200)
_SLACK32 = np.float32(2e-6)  # the float32 box test's slack, in units of the segment


@dataclass(frozen=True)
class _Object:
    """One object's tests: its frame (None: the axes as they are), its bounding box there,
    grown by the tolerance ((1, 3, 1) each), the boxes certainly inside it ((1, 3, K) each, K
    = 0 unless it is closed) and its hierarchy."""

    frame: np.ndarray | None
    lo: np.ndarray
    hi: np.ndarray
    inner_lo: np.ndarray
    inner_hi: np.ndarray
    tree: bvh.Hierarchy

    @classmethod
    def of(cls, triangles: np.ndarray, eps: float) -> _Object:
        frame = solid.principal_frame(triangles)
        framed = solid.in_frame(triangles, frame)
        points = framed.reshape(-1, 3)
        # The boxes inside and the hierarchy side by side: for a mesh of 200k triangles each
        # takes a quarter of a second.
        inner, tree = both(
            lambda: solid.inner_boxes(framed, eps) if solid.closed(triangles, eps) else np.zeros((0, 2, 3)),
            lambda: bvh.build(triangles, framed, eps))
        return cls(frame=None if (frame == np.eye(3)).all() else frame, lo=(points.min(axis=0) - eps)[None, :, None],
                   hi=(points.max(axis=0) + eps)[None, :, None], inner_lo=inner[:, 0].T[None],
                   inner_hi=inner[:, 1].T[None], tree=tree)

    def blocked(self, p0: np.ndarray, d: np.ndarray, inv: np.ndarray, tmin: np.ndarray, tmax: np.ndarray
                ) -> np.ndarray:
        """(N,) whether segments p0 + t d, tmin < t < tmax (inv = `bvh.inverse(d)`) that meet
        the object's box in the scene's axes cross it."""
        out = np.zeros(len(p0), dtype=bool)
        todo = np.arange(len(p0))
        q0, e = p0, d
        if self.frame is not None:
            q0, e = solid.in_frame(p0, self.frame), solid.in_frame(d, self.frame)
            inv = bvh.inverse(e)
            near = bvh.boxes_crossed(q0, inv, tmin, tmax, self.lo, self.hi)[:, 0]
            todo, q0, e, inv = todo[near], q0[near], e[near], inv[near]
        t0, t1 = tmin[todo], tmax[todo]
        if self.inner_lo.shape[2]:
            # A crossing of the surface lies between a point outside the box and one inside it.
            outside = self._outside(q0 + t0[:, None] * e) | self._outside(q0 + t1[:, None] * e)
            sure = outside & bvh.boxes_crossed(q0, inv, t0, t1, self.inner_lo, self.inner_hi).any(axis=1)
            out[todo[sure]] = True
            todo, q0, inv, t0, t1 = todo[~sure], q0[~sure], inv[~sure], t0[~sure], t1[~sure]
        out[todo] = bvh.crossed(self.tree, p0[todo], d[todo], q0, inv, t0, t1)
        return out

    def _outside(self, points: np.ndarray) -> np.ndarray:
        """(N,) whether points in the object's frame lie outside its grown bounding box."""
        return ((points < self.lo[:, :, 0]) | (points > self.hi[:, :, 0])).any(axis=1)


class Occluders:
    """Triangles that can block light, one hierarchy per object, for fast segment queries.

    Segments stop `_END_GAP` tolerances short of both ends, more than the boxes' margin: a
    segment ending on a lamp set into a housing then never even enters the housing's box.
    """

    def __init__(self, triangles: np.ndarray, tri_object: np.ndarray, eps: float) -> None:
        self.eps = eps
        self.objects = [_Object.of(triangles[tri_object == k], eps) for k in np.unique(tri_object)]
        # Every object's bounding box in the scene's axes, by component (1, 3, K): one test of
        # all of them tells which objects a segment may meet.
        corners = [triangles[tri_object == k].reshape(-1, 3) for k in np.unique(tri_object)]
        self.lo = np.stack([c.min(axis=0) - eps for c in corners], axis=1)[None]
        self.hi = np.stack([c.max(axis=0) + eps for c in corners], axis=1)[None]
        self._lo32, self._hi32 = self.lo.astype(np.float32), self.hi.astype(np.float32)

    def blocked(self, p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
        """(N,) whether each open segment p0[i] -> p1[i] hits any triangle."""
        n = len(p0)
        out = np.zeros(n, dtype=bool)
        for i0 in range(0, n, _SEG_CHUNK):
            sl = slice(i0, i0 + _SEG_CHUNK)
            out[sl] = self._blocked_chunk(np.asarray(p0[sl], dtype=np.float64), np.asarray(p1[sl], dtype=np.float64))
        return out

    def _blocked_chunk(self, p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
        d = p1 - p0
        length = np.sqrt(np.einsum("ij,ij->i", d, d))
        tmin = np.minimum(_END_GAP * self.eps / np.maximum(length, 1e-300), 0.5)
        tmax = 1.0 - tmin
        inv = bvh.inverse(d)
        # Every segment against every object's box: in float32, 2.7x as fast. Its rounding is
        # ten-millionths of the segment, so a box it passes within two millionths of is taken
        # as met: an object more to test, never one less (the segments' ends stop short of
        # their surfaces by more, so a lamp's housing is not taken for every ray to the lamp).
        single = (np.asarray(a, dtype=np.float32) for a in (p0, np.clip(inv, -_INV32, _INV32), tmin, tmax))
        near = bvh.boxes_crossed(*single, self._lo32, self._hi32, slack=_SLACK32)
        out = np.zeros(len(p0), dtype=bool)
        for k, obj in enumerate(self.objects):
            todo = np.flatnonzero(near[:, k] & ~out)
            if len(todo):
                out[todo] = obj.blocked(p0[todo], d[todo], inv[todo], tmin[todo], tmax[todo])
        return out
