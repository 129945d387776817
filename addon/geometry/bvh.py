"""A bounding-volume hierarchy that answers "does this segment cross any of these triangles?".

The triangles are ordered by recursive median splits along the widest extent of their
centroids, so every node of binary depth d holds a contiguous range of them, node j the range
[j T >> d, (j + 1) T >> d): the tree needs no pointers. Every third binary level is kept, an
8-ary tree. A batch of segments descends it level by level, each (segment, node) pair testing
the node's children's boxes at once, so the numpy calls are few and large whatever the
triangle count; the pairs that reach a leaf test its triangles exactly (Moller-Trumbore).

The boxes may be taken in a rotated frame (one the object's faces align with, where a flat
face's boxes are thin slabs): the box tests then take the segments in that frame, while the
triangle tests keep the triangles' own coordinates, so the answers do not depend on the frame.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# Triangles per leaf at most: a segment passing a chair's thin legs meets leaf boxes whose every
# triangle it then tests (hotel_chair's removal 11.2 s with 8, 10.4 s with 4, 9.8 s with 2, 10.2 s
# with 1; the box and a 200k-triangle mesh unchanged).
LEAF = 2
_STEP = 3  # binary levels per level of the tree: 2^3 children per node
_PAIRS = 1 << 12  # (segment, node) pairs tested at once: the temporaries stay in cache
_TINY = 1e-200  # a direction component below this is taken as this (no 0 * inf in a box test)


@dataclass(frozen=True)
class Hierarchy:
    """The tree of one set of triangles: per level, the boxes of the children of every node of
    the level above, by component ((nodes, 3, children) each, grown by the margin, in the
    frame), and the leaves' triangles as v0, e1, e2 by component ((leaves, 9, LEAF), in the
    triangles' own coordinates; the last one repeated to fill a leaf: a duplicate cannot change
    "any hit")."""

    lo: tuple[np.ndarray, ...]
    hi: tuple[np.ndarray, ...]
    leaves: np.ndarray


def build(triangles: np.ndarray, framed: np.ndarray, margin: float) -> Hierarchy:
    """The hierarchy of triangles (T, 3, 3), T >= 1, with boxes of the same triangles in the
    frame, `framed` (T, 3, 3), grown by `margin`."""
    n = len(triangles)
    depth = int(np.ceil(np.log2(n / LEAF))) if n > LEAF else 0
    centroids = framed.mean(axis=1)
    order = np.arange(n)
    for d in range(depth):
        starts = _starts(n, d)
        node = np.repeat(np.arange(len(starts) - 1), np.diff(starts))
        c = centroids[order]
        low = np.minimum.reduceat(c, starts[:-1])
        extent = np.maximum.reduceat(c, starts[:-1]) - low
        axis = extent.argmax(axis=1)
        key = c[np.arange(n), axis[node]]
        # Sorted by node, then by the key: one stable sort of the node plus the key scaled into
        # [0, 0.5] within its node (ten times faster than lexsort; keys closer than 1e-10 of
        # their node's extent may swap, which moves no triangle to a wrong side of its split).
        span = extent[np.arange(len(extent)), axis]
        scaled = (key - low[np.arange(len(low)), axis][node]) / np.where(span > 0, 2.0 * span, 1.0)[node]
        order = order[np.argsort(node + scaled, kind="stable")]
    # Pairwise over the three corners: numpy's reduction over an axis of 3 is its slow path.
    corners = framed[order]
    box_lo = np.minimum(np.minimum(corners[:, 0], corners[:, 1]), corners[:, 2]) - margin
    box_hi = np.maximum(np.maximum(corners[:, 0], corners[:, 1]), corners[:, 2]) + margin
    lo, hi = [], []
    above = 0
    first = depth - _STEP * ((depth - 1) // _STEP)
    for d in range(first, depth + 1, _STEP) if depth else ():
        starts = _starts(n, d)[:-1]
        shape = (1 << above, 1 << (d - above), 3)
        lo.append(_by_component(np.minimum.reduceat(box_lo, starts).reshape(shape)))
        hi.append(_by_component(np.maximum.reduceat(box_hi, starts).reshape(shape)))
        above = d
    starts = _starts(n, depth)
    slots = np.minimum(starts[:-1, None] + np.arange(LEAF), starts[1:, None] - 1)
    tris = triangles[order]
    soa = np.concatenate([tris[:, 0], tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]], axis=1)[slots]
    return Hierarchy(tuple(lo), tuple(hi), np.ascontiguousarray(soa.transpose(0, 2, 1)))


def _starts(n: int, d: int) -> np.ndarray:
    """(2^d + 1,) the first triangle of every node of binary depth d, then n."""
    return (np.arange((1 << d) + 1, dtype=np.int64) * n) >> d


def _by_component(boxes: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(boxes.transpose(0, 2, 1))


def inverse(d: np.ndarray) -> np.ndarray:
    """1 / d for the box tests, finite: a zero component becomes a huge one of either sign,
    which tells inside from outside a slab as an infinite one would, without 0 * inf."""
    return 1.0 / np.where(np.abs(d) < _TINY, np.where(d < 0.0, -_TINY, _TINY), d)


def boxes_crossed(q0: np.ndarray, inv: np.ndarray, tmin: np.ndarray, tmax: np.ndarray, lo: np.ndarray,
                  hi: np.ndarray, *, slack: float = 0.0) -> np.ndarray:
    """(N, B) whether segment q0 + t d, tmin <= t <= tmax, (inv = `inverse(d)`, all (N, ...))
    meets box b, given by component: lo, hi (N or 1, 3, B); with `slack`, or comes within that
    (in units of t) of meeting it."""
    near, far = tmin[:, None], tmax[:, None]
    for c in range(3):
        o, k = q0[:, c, None], inv[:, c, None]
        a = (lo[:, c] - o) * k
        b = (hi[:, c] - o) * k
        near = np.maximum(near, np.minimum(a, b))
        far = np.minimum(far, np.maximum(a, b))
    return near <= far + slack


def crossed(tree: Hierarchy, p0: np.ndarray, d: np.ndarray, q0: np.ndarray, inv: np.ndarray, tmin: np.ndarray,
            tmax: np.ndarray) -> np.ndarray:
    """(N,) whether segment p0 + t d, tmin < t < tmax, crosses any of the tree's triangles;
    q0 and inv = `inverse` of the direction are the segment in the boxes' frame. The root's
    box is not tested: the segments given should already meet it."""
    seg = np.arange(len(p0))
    node = np.zeros(len(p0), dtype=np.int64)
    for lo, hi in zip(tree.lo, tree.hi, strict=True):
        seg, node = _children(seg, node, lo, hi, q0, inv, tmin, tmax)
    out = np.zeros(len(p0), dtype=bool)
    for i0 in range(0, len(seg), _PAIRS):
        s = seg[i0 : i0 + _PAIRS]
        hit = _moller_trumbore(p0[s], d[s], tree.leaves[node[i0 : i0 + _PAIRS]], tmin[s], tmax[s])
        out[s[hit]] = True
    return out


def _children(seg, node, lo, hi, q0, inv, tmin, tmax) -> tuple[np.ndarray, np.ndarray]:
    """The (segment, child) pairs whose boxes the pairs' segments meet, of the pairs (seg, node)."""
    width = lo.shape[2]
    out_s, out_n = [seg[:0]], [node[:0]]
    per = max(1, _PAIRS // width)
    for i0 in range(0, len(seg), per):
        s, parent = seg[i0 : i0 + per], node[i0 : i0 + per]
        r, child = np.nonzero(boxes_crossed(q0[s], inv[s], tmin[s], tmax[s], lo[parent], hi[parent]))
        out_s.append(s[r])
        out_n.append(parent[r] * width + child)
    return np.concatenate(out_s), np.concatenate(out_n)


def _moller_trumbore(o: np.ndarray, d: np.ndarray, tri: np.ndarray, tmin: np.ndarray, tmax: np.ndarray) -> np.ndarray:
    """(P,) whether segment p crosses any of its leaf's triangles, given by component (P, 9, LEAF)."""
    ox, oy, oz = (o[:, i, None] for i in range(3))
    dx, dy, dz = (d[:, i, None] for i in range(3))
    v0x, v0y, v0z, ax, ay, az, bx, by, bz = (tri[:, i] for i in range(9))
    px, py, pz = dy * bz - dz * by, dz * bx - dx * bz, dx * by - dy * bx
    det = ax * px + ay * py + az * pz
    ok = np.abs(det) > 1e-20
    inv = 1.0 / np.where(ok, det, 1.0)
    tx, ty, tz = ox - v0x, oy - v0y, oz - v0z
    u = (tx * px + ty * py + tz * pz) * inv
    qx, qy, qz = ty * az - tz * ay, tz * ax - tx * az, tx * ay - ty * ax
    v = (dx * qx + dy * qy + dz * qz) * inv
    t = (bx * qx + by * qy + bz * qz) * inv
    hit = ok & (u >= 0.0) & (v >= 0.0) & (u + v <= 1.0) & (t > tmin[:, None]) & (t < tmax[:, None])
    return hit.any(axis=1)
