"""Plane polygons (n, 2) in order round their boundary: crossings, orientation, containment."""
from __future__ import annotations

import numpy as np


def crossing_edges(points: np.ndarray) -> tuple[int, int] | None:
    """The first pair (i, j), i < j, of edges (edge i runs from corner i to i + 1) that are not
    neighbours and meet, or None when the polygon is simple. Neighbours meeting other than at
    their shared corner (folding back along each other) count too."""
    p = np.asarray(points, dtype=np.float64)
    n = len(p)
    a, b = p, np.roll(p, -1, axis=0)
    i, j = np.triu_indices(n, k=1)
    neighbours = (j == i + 1) | ((i == 0) & (j == n - 1))
    meets = _segments_meet(a[i], b[i], a[j], b[j])
    # Neighbours share a corner; they cross only when they overlap along a line (a fold back).
    folds = neighbours & _folds_back(a[i], b[i], a[j], b[j])
    hit = np.flatnonzero(np.where(neighbours, folds, meets))
    return None if hit.size == 0 else (int(i[hit[0]]), int(j[hit[0]]))


def signed_area(points: np.ndarray) -> float:
    """Positive for counter-clockwise corners (seen from +z)."""
    p = np.asarray(points, dtype=np.float64)
    q = np.roll(p, -1, axis=0)
    return 0.5 * float(np.sum(p[:, 0] * q[:, 1] - q[:, 0] * p[:, 1]))


def contains(points: np.ndarray, point: np.ndarray) -> bool:
    """Whether `point` lies inside the simple polygon (even-odd rule)."""
    p = np.asarray(points, dtype=np.float64) - np.asarray(point, dtype=np.float64)
    q = np.roll(p, -1, axis=0)
    straddles = (p[:, 1] > 0.0) != (q[:, 1] > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = p[:, 0] + (0.0 - p[:, 1]) * (q[:, 0] - p[:, 0]) / (q[:, 1] - p[:, 1])
    return bool(np.count_nonzero(straddles & (x > 0.0)) % 2)


def ray_hit(points: np.ndarray, direction: np.ndarray) -> float | None:
    """Distance along the unit `direction` (2,) from the origin to the polygon's nearest edge
    ahead, or None when the ray leaves through no edge."""
    a = np.asarray(points, dtype=np.float64)
    e = np.roll(a, -1, axis=0) - a
    d = np.asarray(direction, dtype=np.float64)
    denominator = _cross(d, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = _cross(a, e) / denominator  # along the ray
        s = _cross(a, d) / denominator  # along the edge
    ok = (np.abs(denominator) > 1e-12) & (t > 0.0) & (s >= 0.0) & (s <= 1.0)
    return float(t[ok].min()) if ok.any() else None


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def _segments_meet(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    d1, d2 = _cross(b - a, c - a), _cross(b - a, d - a)
    d3, d4 = _cross(d - c, a - c), _cross(d - c, b - c)
    proper = (np.sign(d1) * np.sign(d2) < 0) & (np.sign(d3) * np.sign(d4) < 0)
    touching = ((d1 == 0) & _on_segment(a, b, c)) | ((d2 == 0) & _on_segment(a, b, d)) \
        | ((d3 == 0) & _on_segment(c, d, a)) | ((d4 == 0) & _on_segment(c, d, b))
    return proper | touching


def _on_segment(a: np.ndarray, b: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Whether p, collinear with a and b, lies between them."""
    return np.all((np.minimum(a, b) <= p) & (p <= np.maximum(a, b)), axis=-1)


def _folds_back(a: np.ndarray, b: np.ndarray, c: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Neighbouring edges a-b and c-d (sharing one corner) lying along each other, pointing back."""
    u, v = b - a, d - c
    scale = np.linalg.norm(u, axis=-1) * np.linalg.norm(v, axis=-1)
    parallel = np.abs(_cross(u, v)) <= 1e-9 * scale
    # Sharing a corner and antiparallel when one's end meets the other's start: the path reverses.
    return parallel & (np.sum(u * v, axis=-1) < 0.0)
