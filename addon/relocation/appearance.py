"""The object's appearance carried along the move: each of its points at the new place takes
the photograph's radiance at its old place (where the probe saw it there) divided by the
irradiance there, which removes the shadows other things cast on it as far as the model holds
(thesis 5.2); the insertion lights it with the irradiance at the new place."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry import latlong
from ..geometry.mesh import Geometry
from ..light.radiosity import LUMA, RHO_MAX
from ..removal import Solution
from ..removal.target import Target
from ..removal.trace import Traced
from ..report import Report

_SEEN_DEPTH = 0.02  # a photographed pixel shows a point of the object if its depth agrees to this share


@dataclass(frozen=True)
class Carried:
    """The object's pixels at the new place and what the old place tells about them."""

    pix: np.ndarray  # (N,) flat pixel indices showing the object at the new place
    tri: np.ndarray  # (N,) its triangles there (new geometry)
    bary: np.ndarray  # (N, 2)
    rho: np.ndarray  # (N, 3) its reflectance, from the photograph and the irradiance at the old place
    photographed: np.ndarray  # (N, 3) the photograph's radiance there (the first guess, before relighting)


def carry(old: Solution, geo: Geometry, target: Target, traced: Traced, photo: np.ndarray, rep: Report,
          callbacks: RunCallbacks) -> Carried:
    """Map the object's pixels at the new place (`traced` with the moved geometry `geo`) to its
    old place: radiance, reflectance, and a guard count of the points the photograph does not show."""
    on = traced.obj_h == target.index
    pix = traced.hp[on]
    tri_new = traced.tri_h[on]
    bary = traced.hits.bary.reshape(-1, 2)[pix]
    if not len(pix):
        rep.warn(f"at the new place '{geo.object_names[target.index]}' is hidden from the probe: only its shadow "
                 "and reflected light change the panorama")
        return Carried(pix, tri_new, bary, np.zeros((0, 3)), np.zeros((0, 3)))
    tri_old = _map_rows(old.geo, geo, tri_new)
    known = tri_old >= 0
    radiance = np.zeros((len(pix), 3))
    seen = np.zeros(len(pix), dtype=bool)
    e_old = np.zeros((len(pix), 3))
    if known.any():
        radiance[known], seen[known] = _photographed(old, photo, tri_old[known], bary[known])
        e_old[known] = old.irradiance(tri_old[known], bary[known], callbacks)
    rho = _reflectance(old, radiance, seen, e_old, rep)
    return Carried(pix, tri_new, bary, rho, radiance)


def _reflectance(old: Solution, radiance: np.ndarray, seen: np.ndarray, e_old: np.ndarray, rep: Report
                 ) -> np.ndarray:
    """(N, 3) reflectance of the object's points from their photographed radiance (N, 3) and
    irradiance (N, 3) at the old place; `radiance` is completed where it is not known."""
    y_old = e_old @ LUMA
    lit = seen & (y_old > 1e-3 * max(float(np.median(y_old[seen])) if seen.any() else 0.0, 1e-30))
    implied = np.pi * radiance[lit] / np.maximum(e_old[lit], 1e-30)
    rep.guard("object_reflectance_clamped_pixels", int((implied > RHO_MAX).any(axis=1).sum()))
    rho = np.zeros((len(radiance), 3))
    rho[lit] = np.clip(implied, 0.0, RHO_MAX)
    if lit.any():
        rho[~lit] = np.median(rho[lit], axis=0)
        radiance[~lit] = np.median(radiance[lit], axis=0)
    else:
        rho[:] = np.median(old.room.rho[old.room.senders.on_removed], axis=0)
        radiance[:] = rho * np.median(e_old, axis=0) / np.pi
        rep.warn("the probe did not see the object well enough to take its appearance from the panorama: "
                 "it is shown with its estimated mean reflectance")
    unseen = int((~lit).sum())
    if unseen:
        # Points the photograph does not show (a nearer object is seen more from above) or
        # shows too dark to measure (its own deep shadow) take the object's median.
        rep.guard("object_pixels_without_photograph", unseen)
    return rho


def _map_rows(old: Geometry, new: Geometry, tri_new: np.ndarray) -> np.ndarray:
    """Triangle indices of the old geometry for triangles of the new one (the same rows of the
    scene's triangle list; -1 where the old geometry dropped the row)."""
    index = np.full(int(max(old.source.max(), new.source.max())) + 1, -1, dtype=np.int64)
    index[old.source] = np.arange(len(old.source))
    return index[new.source[tri_new]]


def _photographed(old: Solution, photo: np.ndarray, tri: np.ndarray, bary: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) the photograph's radiance at points of the object given in the old geometry, and
    (N,) whether the probe saw them there (bilinear over the neighbouring pixels that show the
    object at the point's depth)."""
    traced, width, height = old.traced, old.traced.width, old.traced.height
    tris = old.geo.triangles[tri]
    points = tris[:, 0] + bary[:, :1] * (tris[:, 1] - tris[:, 0]) + bary[:, 1:] * (tris[:, 2] - tris[:, 0])
    depth = np.linalg.norm(points, axis=1)
    u, v = latlong.direction_to_uv(points / np.maximum(depth, 1e-300)[:, None])
    x = u * width - 0.5
    y = (1.0 - v) * height - 0.5
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    hit_tri = traced.hits.tri
    on_object = (hit_tri >= 0) & (old.geo.tri_object[np.maximum(hit_tri, 0)] == old.target.index)
    total = np.zeros((len(points), 3))
    weight = np.zeros(len(points))
    for dy in (0, 1):
        for dx in (0, 1):
            yy = np.clip(y0 + dy, 0, height - 1)
            xx = (x0 + dx) % width
            w = (1.0 - np.abs(x - (x0 + dx))) * (1.0 - np.abs(y - (y0 + dy)))
            ok = on_object[yy, xx] & (np.abs(traced.hits.distance[yy, xx] - depth) <= _SEEN_DEPTH * depth)
            w = np.where(ok, w, 0.0)
            total += w[:, None] * photo[yy, xx]
            weight += w
    seen = weight > 0.25
    return np.where(seen[:, None], total / np.maximum(weight, 1e-300)[:, None], 0.0), seen
