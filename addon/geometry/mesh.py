"""Proxy geometry in the probe frame: triangles with oriented normals, areas and object bounds.

The engine works in the probe frame, p' = R (p - c): the probe centre is the origin and the
panorama's own axes are the frame's axes, so a pixel's direction needs no rotation. Rotations
keep every distance and angle, so form factors and visibility are unchanged.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..errors import DimredError
from .raycast import Projection, project


@dataclass
class Geometry:
    """Triangles (T, 3, 3) in the probe frame with unit normals pointing to the lit side."""

    triangles: np.ndarray
    normals: np.ndarray
    areas: np.ndarray
    tri_object: np.ndarray
    object_names: list[str]
    scale: float  # size of the scene (bounding-box diagonal), for tolerances
    dropped_degenerate: int
    source: np.ndarray  # (T,) row of each triangle in the scene's triangle list

    @cached_property
    def projection(self) -> Projection:
        """The triangles as the probe sees them (`raycast.project`), for every trace of them."""
        return project(self.triangles)

    def object_bounds(self, index: int) -> tuple[np.ndarray, np.ndarray]:
        tris = self.triangles[self.tri_object == index].reshape(-1, 3)
        return tris.min(axis=0), tris.max(axis=0)

    def bounding_sphere(self, index: int) -> tuple[np.ndarray, float]:
        lo, hi = self.object_bounds(index)
        centre = 0.5 * (lo + hi)
        pts = self.triangles[self.tri_object == index].reshape(-1, 3)
        return centre, float(np.linalg.norm(pts - centre, axis=1).max())


def to_probe_frame(points: np.ndarray, center: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """p' = R (p - c) for points (..., 3)."""
    return (np.asarray(points, dtype=np.float64) - np.asarray(center, dtype=np.float64)) @ np.asarray(
        rotation, dtype=np.float64
    ).T


def _orient(triangles: np.ndarray, normals: np.ndarray, tri_object: np.ndarray, n_objects: int) -> np.ndarray:
    """Flip normals so that each points to the side light is exchanged on.

    Surfaces around the probe (a room shell, or any flat object) are seen by the probe from
    their lit side, so they face the origin. A solid object that does not enclose the probe
    (furniture) is lit from outside: its normals point outward, which the sign of its
    enclosed volume tells whatever way the artist modelled it.
    """
    out = normals.copy()
    centroids = triangles.mean(axis=1)
    for k in range(n_objects):
        sel = tri_object == k
        if not sel.any():
            continue
        pts = triangles[sel].reshape(-1, 3)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        extent = hi - lo
        flat = extent.min() <= 1e-3 * max(extent.max(), 1e-12)
        encloses = bool(np.all(lo < 0.0) and np.all(hi > 0.0))
        if flat or encloses:
            facing = np.einsum("ij,ij->i", out[sel], -centroids[sel])
            out[sel] = np.where((facing < 0.0)[:, None], -out[sel], out[sel])
        else:
            t = triangles[sel] - pts.mean(axis=0)
            volume = np.einsum("ij,ij->i", t[:, 0], np.cross(t[:, 1], t[:, 2])).sum()
            if volume < 0.0:
                out[sel] = -out[sel]
    return out


def build_geometry(
    triangles: np.ndarray, tri_object: np.ndarray, object_names: list[str], center: np.ndarray, rotation: np.ndarray
) -> Geometry:
    """Probe-frame geometry with degenerate triangles dropped and normals oriented."""
    if len(triangles) == 0:
        raise DimredError("the scene has no mesh geometry: model the room (floor, walls) as meshes")
    tris = to_probe_frame(triangles, center, rotation)
    if not np.isfinite(tris).all():
        raise DimredError("the scene geometry contains NaN or infinite vertex coordinates")
    cross = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    twice_area = np.linalg.norm(cross, axis=1)
    scale = float(np.linalg.norm(tris.reshape(-1, 3).max(axis=0) - tris.reshape(-1, 3).min(axis=0)))
    # Below (1e-4 of the scene's size)^2 a triangle covers far less than a pixel of any panorama
    # and carries no light worth a patch; slivers of that area would only unsettle the patches.
    keep = twice_area > 1e-8 * max(scale, 1e-9) ** 2
    tris, cross, twice_area = tris[keep], cross[keep], twice_area[keep]
    tri_object = np.asarray(tri_object)[keep]
    normals = cross / twice_area[:, None]
    normals = _orient(tris, normals, tri_object, len(object_names))
    return Geometry(
        triangles=tris,
        normals=normals,
        areas=0.5 * twice_area,
        tri_object=tri_object,
        object_names=list(object_names),
        scale=max(scale, 1e-9),
        dropped_degenerate=int((~keep).sum()),
        source=np.flatnonzero(keep),
    )


def plane_of_object(geometry: Geometry, index: int, *, tolerance: float = 1e-3) -> tuple[np.ndarray, float] | None:
    """(unit normal, offset) if all the object's triangles lie in one plane, else None."""
    sel = geometry.tri_object == index
    if not sel.any():
        return None
    n = geometry.normals[sel]
    w = geometry.areas[sel]
    mean_n = (n * w[:, None]).sum(axis=0)
    norm = np.linalg.norm(mean_n)
    if norm <= 1e-12:
        return None
    mean_n /= norm
    pts = geometry.triangles[sel].reshape(-1, 3)
    d = pts @ mean_n
    size = np.linalg.norm(pts.max(axis=0) - pts.min(axis=0))
    if np.ptp(d) > tolerance * max(size, 1e-9):
        return None
    return mean_n, float(d.mean())


def boundary_objects(geometry: Geometry, witnesses: np.ndarray) -> np.ndarray:
    """(K,) whether an object bounds the scene: every witness point lies on the lit side of
    every one of its triangles (a convex room shell, a flat wall or floor).

    Such an object can never block a segment between two points of the room, so shadow rays
    need not test it: it is most of the triangles a ray would otherwise meet.
    """
    k = len(geometry.object_names)
    out = np.zeros(k, dtype=bool)
    tol = 1e-6 * geometry.scale
    for obj in range(k):
        sel = geometry.tri_object == obj
        if not sel.any():
            continue
        n = geometry.normals[sel]
        off = np.einsum("ij,ij->i", n, geometry.triangles[sel, 0])
        out[obj] = _all_on_lit_side(witnesses, n, off, tol)
    return out


_PRODUCT_ENTRIES = 1 << 22  # witness-plane heights computed at once (32 MB of float64)


def _all_on_lit_side(witnesses: np.ndarray, normals: np.ndarray, offsets: np.ndarray, tol: float) -> bool:
    """Whether every witness (W, 3) lies on the lit side of every plane (normals (N, 3), offsets
    (N,)). A spread-out sample of the witnesses goes first, so a detailed object that does not
    bound the room (most of them) is rejected after a few products; the products are chunked so
    a 50k-triangle object never needs a (W, N) matrix."""
    rows = max(1, _PRODUCT_ENTRIES // max(len(normals), 1))
    sample = witnesses[:: max(1, len(witnesses) // 1024)]
    for points in (sample, witnesses):
        for i0 in range(0, len(points), rows):
            if ((points[i0 : i0 + rows] @ normals.T - offsets) < -tol).any():
                return False
    return True


def surface_keys(geometry: Geometry, *, angle_tolerance: float = 1e-3) -> np.ndarray:
    """(T,) an id shared by the triangles of one object that lie in one plane."""
    scale = geometry.scale
    off = np.einsum("ij,ij->i", geometry.normals, geometry.triangles[:, 0])
    key = np.concatenate(
        [
            geometry.tri_object[:, None].astype(np.float64),
            np.round(geometry.normals / angle_tolerance),
            np.round(off / (1e-3 * scale))[:, None],
        ],
        axis=1,
    )
    # np.unique's ids (rows in lexicographic order), by a sort per column: np.unique(axis=0)
    # compares whole rows and took 0.4 s for 200k triangles, this 0.05 s.
    order = np.lexsort(key.T[::-1])
    ordered = key[order]
    first = np.ones(len(key), dtype=bool)
    first[1:] = (ordered[1:] != ordered[:-1]).any(axis=1)
    ids = np.empty(len(key), dtype=np.int64)
    ids[order] = np.cumsum(first) - 1
    return ids


def surfaces_of(keys: np.ndarray, tri: np.ndarray) -> np.ndarray:
    """The surface key (`keys`, per triangle) of each triangle index in `tri`, -1 where it is -1
    (nothing hit), in the keys' dtype."""
    return np.where(tri >= 0, keys[np.maximum(tri, 0)], -1)
