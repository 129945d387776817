"""What each panorama pixel sees from the probe centre, with the object and without it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import latlong
from ..geometry.mesh import Geometry
from ..geometry.raycast import PanoramaHits, trace_panorama
from ..report import Report
from .target import Target


@dataclass(frozen=True)
class Behind:
    """What the probe would see where the object was: per panorama pixel (flat, H*W) and per
    revealed pixel (the hidden pixels that see a surface once the object is gone)."""

    tri_without: np.ndarray  # (H*W,) first triangle hit without the object, -1 for none
    distance_without: np.ndarray  # (H*W,) its distance (0 where nothing is traced)
    revealed: np.ndarray  # (K,) rows of the hit pixels (the `_h` arrays) that are revealed
    tri: np.ndarray  # (K,) triangle each revealed pixel sees
    bary: np.ndarray  # (K, 2) barycentric weights of vertices 1 and 2 there
    points: np.ndarray  # (K, 3) the point it sees

    @classmethod
    def nothing(cls, pixels: int) -> Behind:
        return cls(np.full(pixels, -1, dtype=np.int64), np.zeros(pixels), np.zeros(0, dtype=np.int64),
                   np.zeros(0, dtype=np.int64), np.zeros((0, 2)), np.zeros((0, 3)))


@dataclass(frozen=True)
class Traced:
    """The first hit of every pixel's ray; the `_h` arrays hold one row per hit pixel."""

    hits: PanoramaHits
    hp: np.ndarray  # (N,) flat panorama index of each hit pixel
    tri_h: np.ndarray  # (N,) triangle it sees
    obj_h: np.ndarray  # (N,) object it sees
    points_h: np.ndarray  # (N, 3) the point it sees, probe frame
    normals_h: np.ndarray  # (N, 3) the normal there
    hidden_h: np.ndarray  # (N,) bool: not relit: filled (the object and its silhouette) or kept
    kept_h: np.ndarray  # (N,) bool: the proxy's pixels the photograph does not show as the object (left as they are)
    beyond_h: np.ndarray  # (N,) bool: filled, the photograph showing the object there, the proxy a pixel away or more
    hidden_map: np.ndarray  # (H, W) bool: the filled pixels per panorama pixel
    behind: Behind

    @property
    def height(self) -> int:
        return self.hits.tri.shape[0]

    @property
    def width(self) -> int:
        return self.hits.tri.shape[1]

    def panorama_rows(self, image: np.ndarray) -> np.ndarray:
        """(N, 3) float64 values of an (H, W, 3) image at the hit pixels."""
        return image.reshape(-1, 3)[self.hp].astype(np.float64)


def trace(geo: Geometry, target: Target, width: int, height: int, *, fill: bool, rep: Report,
          shown: np.ndarray | None = None) -> Traced:
    """What each pixel sees. With `fill` (a removal), the pixels the object shows in (`shown`,
    (H, W) bool: the photograph's object, default the proxy's silhouette) and the pixels around
    them are hidden (filled, not relit), and what is behind them is traced. Pixels of the
    proxy outside `shown` are kept as the photograph shows them."""
    hits = trace_panorama(geo.triangles, width, height, projection=geo.projection)
    flat_tri = hits.tri.ravel()
    hp = np.flatnonzero(flat_tri >= 0)
    tri_h = flat_tri[hp]
    obj_h = geo.tri_object[tri_h]
    on_object = np.zeros(height * width, dtype=bool)
    on_object[hp[obj_h == target.index]] = True
    on_object = on_object.reshape(height, width)
    filled = on_object if shown is None or not fill else shown
    # A pixel on the object's silhouette mixes it with what is behind; the ratio form would
    # scale the object's share of it too, so it is filled like the pixels the object covers.
    if fill:
        filled = latlong.dilate(filled, 1)
    filled_h = filled.ravel()[hp]
    kept_h = on_object.ravel()[hp] & ~filled_h
    beyond_h = filled_h & ~latlong.dilate(on_object, 1).ravel()[hp]
    hidden_h = filled_h | kept_h
    hidden_map = np.zeros(height * width, dtype=bool)
    hidden_map[hp[filled_h]] = True
    missing = len(flat_tri) - len(hp)
    if missing:
        rep.warn(f"{missing} panorama pixels see no proxy geometry (open room?); they are left unchanged")
    rep.info["hidden_pixels"] = int(filled_h.sum())
    if kept_h.any():
        rep.info["kept_object_pixels"] = int(kept_h.sum())
    behind = Behind.nothing(height * width)
    if fill and filled_h.any():
        behind = _behind(geo, target, width, height, hp, filled_h, rep)
    return Traced(hits=hits, hp=hp, tri_h=tri_h, obj_h=obj_h,
                  points_h=hits.points.reshape(-1, 3)[hp], normals_h=geo.normals[tri_h], hidden_h=hidden_h,
                  kept_h=kept_h, beyond_h=beyond_h, hidden_map=hidden_map.reshape(height, width), behind=behind)


def _behind(geo: Geometry, target: Target, width: int, height: int, hp: np.ndarray, hidden_h: np.ndarray,
            rep: Report) -> Behind:
    """The surfaces to fill: what the hidden pixels see once the object is gone."""
    keep = np.flatnonzero(geo.tri_object != target.index)
    hits = trace_panorama(geo.triangles[keep], width, height, projection=geo.projection.take(keep))
    flat = hits.tri.ravel()
    tri_without = np.full(height * width, -1, dtype=np.int64)
    tri_without[flat >= 0] = keep[flat[flat >= 0]]
    hidden = np.flatnonzero(hidden_h)
    revealed = hidden[tri_without[hp[hidden]] >= 0]
    pix = hp[revealed]
    unseen = len(hidden) - len(revealed)
    if unseen:
        rep.warn(f"{unseen} pixels of the object see no proxy geometry behind it; they are left unchanged")
    return Behind(tri_without=tri_without, distance_without=hits.distance.ravel(), revealed=revealed,
                  tri=tri_without[pix], bary=hits.bary.reshape(-1, 2)[pix], points=hits.points.reshape(-1, 3)[pix])
