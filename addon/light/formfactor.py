"""Analytic form factors from a differential receiver area to a triangular sender.

Lambert's contour formula, F = 1/(2 pi) sum_edges angle_k * (n . unit(r_k x r_k+1)), is exact
for a polygon entirely above the receiver's tangent plane. The sender is first clipped to that
half-space ("horizon clipping"), so the result stays exact and finite even when sender and
receiver touch (a box standing on the floor), where the point-to-point kernel
cos*cos*A/(pi d^2) diverges. Far from the receiver (`FAR` radii) that kernel, taken at the
edge midpoints, is as good and much cheaper.
"""
from __future__ import annotations

import numpy as np

# Pairs evaluated per chunk: bounds the (pairs, 6, 3) float64 temporaries to ~50 MB.
_CHUNK = 250_000
# A triangle wholly above the horizon and farther than this many times its radius takes the
# kernel cos*cos/(pi d^2) at its edge midpoints (exact for a quadratic kernel): the error
# is of order (radius / d)^3, under 0.5 % there, at a tenth of the contour's cost.
FAR = 6.0


def _forward_fill(valid: np.ndarray) -> np.ndarray:
    """Index of the nearest valid slot at or before each slot, cyclically (valid: (..., K))."""
    k = valid.shape[-1]
    idx = np.where(valid, np.arange(k), -1)
    idx = np.maximum.accumulate(idx, axis=-1)
    last = np.where(valid, np.arange(k), -1).max(axis=-1, keepdims=True)
    return np.where(idx < 0, last, idx)


def _clip_and_integrate(rel: np.ndarray, n: np.ndarray, eps: float) -> np.ndarray:
    """Form factors for triangles `rel` (P, 3, 3), vertices relative to the receiver, normal n (P, 3)."""
    h = np.einsum("pkc,pc->pk", rel, n)  # height of each vertex above the tangent plane
    inside = h > eps
    following = np.roll(np.arange(3), -1)  # the edge from vertex k runs to vertex following[k]
    h_next = h[:, following]
    crossing = inside != inside[:, following]
    denom = np.where(crossing, h - h_next, 1.0)
    s = np.where(crossing, (h - eps) / denom, 0.0)
    cut = rel + s[..., None] * (rel[:, following] - rel)
    # Sutherland-Hodgman on one plane, as 6 fixed slots (vertex k if inside, then the cut on
    # edge k if the edge crosses); empty slots repeat a valid neighbour so they add nothing.
    slots = np.stack([rel, cut], axis=2).reshape(len(rel), 6, 3)
    valid = np.stack([inside, crossing], axis=2).reshape(len(rel), 6)
    slots = np.take_along_axis(slots, _forward_fill(valid)[..., None], axis=1)
    return np.where(valid.any(axis=1), _contour(slots, n), 0.0)


def _contour(polygon: np.ndarray, n: np.ndarray) -> np.ndarray:
    """Lambert's formula for polygons (P, K, 3) wholly above the tangent plane (vertices relative
    to the receiver, any length: the edge angle and the projected direction are scale-free).
    By component on (P, K) arrays: np.cross and einsum on (P, K, 3) ones cost twice as much."""
    ax, ay, az = polygon[..., 0], polygon[..., 1], polygon[..., 2]
    bx, by, bz = (np.roll(c, -1, axis=1) for c in (ax, ay, az))
    cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
    cross_len = np.sqrt(cx * cx + cy * cy + cz * cz)
    angle = np.arctan2(cross_len, ax * bx + ay * by + az * bz)
    proj = cx * n[:, 0, None] + cy * n[:, 1, None] + cz * n[:, 2, None]
    contrib = np.where(cross_len > 1e-300, angle * proj / np.where(cross_len > 1e-300, cross_len, 1.0), 0.0)
    return np.abs(contrib.sum(axis=1)) / (2.0 * np.pi)


def _unit(v: np.ndarray) -> np.ndarray:
    """Rows scaled to length 1: a whole triangle's contour is integrated on the unit sphere."""
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _pairs(rel: np.ndarray, n: np.ndarray, sender_normals: np.ndarray | None, eps: float) -> np.ndarray:
    """Form factors of rows rel (P, 3, 3) with receiver normals n (P, 3); most pairs need no clip.
    The tests by component on (P, 3) arrays: reductions and einsum over an axis of 3 cost
    several times the arithmetic."""
    x, y, z = rel[..., 0], rel[..., 1], rel[..., 2]  # (P, 3): the three vertices
    h = x * n[:, 0, None] + y * n[:, 1, None] + z * n[:, 2, None]
    above = h > eps
    some = above[:, 0] | above[:, 1] | above[:, 2]
    if sender_normals is not None:
        facing = x[:, 0] * sender_normals[:, 0] + y[:, 0] * sender_normals[:, 1] + z[:, 0] * sender_normals[:, 2]
        some &= -facing > 0.0
    whole = some & above[:, 0] & above[:, 1] & above[:, 2]
    part = some & ~whole
    f = np.zeros(len(rel))
    whole = np.flatnonzero(whole)
    rel_w = rel[whole]
    centre = [(c[whole, 0] + c[whole, 1] + c[whole, 2]) / 3 for c in (x, y, z)]
    gaps = [sum((rel_w[:, k, c] - centre[c]) ** 2 for c in range(3)) for k in range(3)]
    reach2 = np.maximum(np.maximum(gaps[0], gaps[1]), gaps[2])
    far = centre[0] ** 2 + centre[1] ** 2 + centre[2] ** 2 > FAR**2 * reach2
    f[whole[far]] = _midpoints(rel_w[far], n[whole[far]])
    f[whole[~far]] = _contour(_unit(rel_w[~far]), n[whole[~far]])
    if part.any():
        f[part] = _clip_and_integrate(rel[part], n[part], eps)
    return f


def _midpoints(rel: np.ndarray, n: np.ndarray) -> np.ndarray:
    """The point-to-point kernel of triangles rel (P, 3, 3) wholly above the horizon of
    receivers with normals n (P, 3), integrated at the triangles' edge midpoints."""
    area = 0.5 * np.cross(rel[:, 1] - rel[:, 0], rel[:, 2] - rel[:, 0])  # (P, 3) area times normal
    mid = 0.5 * (rel + np.roll(rel, -1, axis=1))  # (P, 3, 3)
    d2 = np.einsum("pkc,pkc->pk", mid, mid)
    kernel = np.einsum("pkc,pc->pk", mid, n) * np.abs(np.einsum("pkc,pc->pk", mid, area)) / (d2 * d2)
    return kernel.sum(axis=1) / (3.0 * np.pi)


def point_to_triangle(
    points: np.ndarray,
    normals: np.ndarray,
    triangles: np.ndarray,
    sender_normals: np.ndarray | None = None,
    *,
    eps: float = 1e-9,
) -> np.ndarray:
    """(R, S) form factors from receiver points (R, 3) with unit normals (R, 3) to triangles (S, 3, 3).

    With `sender_normals` (S, 3) the senders are one-sided: a receiver behind a sender's plane
    gets 0. Receivers in the sender's plane get 0 (they see it edge-on).
    """
    points = np.asarray(points, dtype=np.float64)
    normals = np.asarray(normals, dtype=np.float64)
    triangles = np.asarray(triangles, dtype=np.float64)
    r, s = len(points), len(triangles)
    out = np.zeros((r, s))
    if r == 0 or s == 0:
        return out
    senders = None if sender_normals is None else np.asarray(sender_normals, dtype=np.float64)
    rows_per_chunk = max(1, _CHUNK // s)
    for r0 in range(0, r, rows_per_chunk):
        x = points[r0 : r0 + rows_per_chunk]
        rel = (triangles[None, :, :, :] - x[:, None, None, :]).reshape(-1, 3, 3)
        pair_normals = np.repeat(normals[r0 : r0 + rows_per_chunk], s, axis=0)
        pair_senders = None if senders is None else np.tile(senders, (len(x), 1))
        out[r0 : r0 + len(x)] = _pairs(rel, pair_normals, pair_senders, eps).reshape(len(x), s)
    return out


def paired_point_to_triangle(
    points: np.ndarray, normals: np.ndarray, triangles: np.ndarray, sender_normals: np.ndarray | None = None
) -> np.ndarray:
    """Form factors for matching rows: point i with normal i to triangle i (all (N, ...))."""
    points = np.asarray(points, dtype=np.float64)
    out = np.zeros(len(points))
    for i0 in range(0, len(points), _CHUNK):
        sl = slice(i0, i0 + _CHUNK)
        rel = np.asarray(triangles[sl], dtype=np.float64) - points[sl, None, :]
        senders = None if sender_normals is None else np.asarray(sender_normals[sl], dtype=np.float64)
        out[sl] = _pairs(rel, np.asarray(normals[sl], dtype=np.float64), senders, 1e-9)
    return out
