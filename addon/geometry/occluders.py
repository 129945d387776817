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

from . import bvh, solid

_SEG_CHUNK = 200_000
_END_GAP = 30.0  # segment ends stop this many tolerances short of the surfaces they join


@dataclass(frozen=True)
class _Object:
    frame: np.ndarray  # (3, 3) rows: the axes of the frame its boxes are taken in
    lo: np.ndarray  # (1, 3, 1) its bounding box in the frame, grown by the tolerance
    hi: np.ndarray
    inner: np.ndarray  # (1, 3, K) boxes certainly inside it (K = 0 unless it is closed)
    inner_hi: np.ndarray
    tree: bvh.Hierarchy


def _object(triangles: np.ndarray, eps: float) -> _Object:
    frame = solid.principal_frame(triangles)
    framed = solid.in_frame(triangles, frame)
    points = framed.reshape(-1, 3)
    inner = solid.inner_boxes(framed, eps) if solid.closed(triangles, eps) else np.zeros((0, 2, 3))
    return _Object(frame=frame, lo=(points.min(axis=0) - eps)[None, :, None],
                   hi=(points.max(axis=0) + eps)[None, :, None], inner=inner[:, 0].T[None],
                   inner_hi=inner[:, 1].T[None], tree=bvh.build(triangles, framed, eps))


class Occluders:
    """Triangles that can block light, one hierarchy per object, for fast segment queries.

    Segments stop `_END_GAP` tolerances short of both ends, more than the boxes' margin: a
    segment ending on a lamp set into a housing then never even enters the housing's box.
    """

    def __init__(self, triangles: np.ndarray, tri_object: np.ndarray, eps: float) -> None:
        self.eps = eps
        self.objects = [_object(triangles[tri_object == k], eps) for k in np.unique(tri_object)]

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
        length = np.linalg.norm(d, axis=1)
        tmin = np.minimum(_END_GAP * self.eps / np.maximum(length, 1e-300), 0.5)
        tmax = 1.0 - tmin
        out = np.zeros(len(p0), dtype=bool)
        for obj in self.objects:
            todo = np.flatnonzero(~out)
            q0, e = solid.in_frame(p0[todo], obj.frame), solid.in_frame(d[todo], obj.frame)
            inv = bvh.inverse(e)
            near = bvh.boxes_crossed(q0, inv, tmin[todo], tmax[todo], obj.lo, obj.hi)[:, 0]
            todo, q0, e, inv = todo[near], q0[near], e[near], inv[near]
            t0, t1 = tmin[todo], tmax[todo]
            if obj.inner.shape[2]:
                # A crossing of the surface lies between a point outside the box and one inside it.
                outside = _outside(q0 + t0[:, None] * e, obj) | _outside(q0 + t1[:, None] * e, obj)
                sure = outside & bvh.boxes_crossed(q0, inv, t0, t1, obj.inner, obj.inner_hi).any(axis=1)
                out[todo[sure]] = True
                todo, q0, e, inv, t0, t1 = todo[~sure], q0[~sure], e[~sure], inv[~sure], t0[~sure], t1[~sure]
            out[todo] = bvh.crossed(obj.tree, p0[todo], d[todo], q0, inv, t0, t1)
        return out


def _outside(points: np.ndarray, obj: _Object) -> np.ndarray:
    """(N,) whether points in the object's frame lie outside its grown bounding box."""
    return ((points < obj.lo[:, :, 0]) | (points > obj.hi[:, :, 0])).any(axis=1)
