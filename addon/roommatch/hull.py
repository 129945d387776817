"""A one-view hull: the part of a base of upright boxes that the probe sees through an object's
outline, so that the proxy's silhouette is the outline wherever the base covers it, without
pretending that an armchair is a box.

A column of the lat-long panorama is a vertical half-plane through the probe; in it the outline's
run of pixels (top to bottom) is a wedge between two rays, and a box standing on the floor is a
rectangle (its near and far sides where the ray meets its footprint, the floor and its top). Their
intersection is the hull's section in that column: above the floor and the wedge's lower ray,
below the box's top and the wedge's upper ray. Each column's section stands in the half-plane
of its pixels' centres and the sections are joined column to column: a pixel centre's ray meets
the mesh where it crosses its column's section (on the edges of the faces either side, which the
tracers count). The mesh is closed, every face's normal outwards.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry.raycast import trace_panorama
from .meshes import MeshData
from .object_box import Outline
from .projection import project

_WELD = 1e-4  # metres: vertices are welded on this grid (well above any scene's tolerance)
_STEP = 5e-4  # metres: a step in the base's height becomes a slope this wide either side
_MAX_COLUMNS = 160  # columns of the outline the hull follows at most (wider outlines are merged in groups)
_FEATURE = np.cos(np.radians(25.0))  # edges between faces turned more than this are drawn


@dataclass(frozen=True)
class Hull:
    """A closed triangle mesh: vertices (v, 3) in metres (world) and triangles (t, 3) of vertex
    indices, counter-clockwise seen from outside."""

    vertices: np.ndarray
    triangles: np.ndarray

    def mesh(self, name: str) -> MeshData:
        return MeshData(name, self.vertices, tuple(map(tuple, self.triangles.tolist())))

    def edges(self) -> np.ndarray:
        """(e, 2, 3) the edges a picture draws: those between faces turned by more than 25
        degrees (the sections' outlines, the base's sides and steps), not the flat ones."""
        v, t = self.vertices, self.triangles
        normal = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
        normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
        pairs = np.sort(np.stack([t, np.roll(t, -1, axis=1)], axis=-1).reshape(-1, 2), axis=1)
        face = np.repeat(np.arange(len(t)), 3)
        order = np.lexsort(pairs.T[::-1])
        pairs, face = pairs[order], face[order]
        # An edge of a closed mesh shared by two faces lists them on consecutive rows.
        shared = np.flatnonzero((pairs[1:] == pairs[:-1]).all(axis=1))
        turned = np.einsum("ij,ij->i", normal[face[shared]], normal[face[shared + 1]]) < _FEATURE
        return v[pairs[shared[turned]]]

    def triangle_corners(self) -> np.ndarray:
        """(t, 3, 3) each triangle's corners."""
        return self.vertices[self.triangles]


def vertical_columns(outline: Outline) -> bool:
    """Whether the outline's pixel columns stand upright in the world (the panorama turned about
    the vertical only): the hull is built of vertical half-planes."""
    r = np.asarray(outline.rotation, dtype=np.float64)
    return bool(np.allclose(r[2], (0.0, 0.0, 1.0), atol=1e-9) and np.allclose(r[:, 2], (0.0, 0.0, 1.0), atol=1e-9))


@dataclass(frozen=True)
class Wedges:
    """Per column of an outline: its azimuth's unit vector (c, 2), the slopes (height per metre
    from the probe) of the rays along the top and bottom edges of the run of pixels it keeps,
    whether it keeps any, and the pixels those runs cover (h, w)."""

    along: np.ndarray
    top: np.ndarray
    bottom: np.ndarray
    kept: np.ndarray
    shown: np.ndarray

    @classmethod
    def of(cls, outline: Outline) -> Wedges:
        """The outline's runs: in each column from its topmost to its lowest pixel, or only its
        longest run where that leaves fewer of the outline's pixels out than filling the gaps
        adds (a chair's wing above the background seen between it and the arm)."""
        shown, d = outline.shown, outline.directions
        h, w = shown.shape
        count = shown.sum(axis=0)
        kept = count > 0
        first = np.argmax(shown, axis=0)
        last = h - 1 - np.argmax(shown[::-1], axis=0)
        # Runs numbered down each column in turn; their lengths and first rows.
        starts = shown & ~np.vstack([np.zeros((1, w), dtype=bool), shown[:-1]])
        ids = np.where(shown.T, np.cumsum(starts.T.ravel()).reshape(w, h), 0)
        lengths = np.bincount(ids.ravel(), minlength=ids.max() + 1)
        lengths[0] = 0
        rows = np.broadcast_to(np.arange(h), (w, h))
        longest = np.argmax(np.where(ids > 0, lengths[ids], -1), axis=1)  # the first row of each column's longest run
        run = lengths[ids[np.arange(w), longest]]
        single = (count - run) < (last - first + 1 - count)
        top = np.where(single, longest, first)
        bottom = np.where(single, longest + run - 1, last)
        covered = kept[None, :] & (rows.T >= top[None, :]) & (rows.T <= bottom[None, :])
        elevation = np.arcsin(np.clip(d[:, w // 2, 2], -1.0, 1.0))
        half = 0.5 * float(np.abs(np.diff(elevation)).mean())
        mid = d[h // 2, :, :2]
        along = mid / np.linalg.norm(mid, axis=1, keepdims=True)
        up = np.minimum(elevation[top] + half, np.radians(89.0))
        down = np.maximum(elevation[bottom] - half, -np.radians(89.0))
        return cls(along, np.tan(up), np.tan(down), kept, covered)


def carve(outline: Outline, wedges: Wedges, boxes: np.ndarray) -> Hull | None:
    """The hull of `outline` within the upright `boxes` ((p, 6) `object_box.silhouette`'s
    parameters, from the probe; adjacent, as a box's or a stepped box's parts); None where no
    column's section is left."""
    span = np.flatnonzero(wedges.kept)
    if not len(span):
        return None
    span = slice(span[0], span[-1] + 1)
    along, top, bottom, kept = wedges.along[span], wedges.top[span], wedges.bottom[span], wedges.kept[span]
    if len(along) > _MAX_COLUMNS:
        along, top, bottom, kept = _grouped(along, top, bottom, kept)
    samples, lower, upper, ok = _sections(along, top, bottom, kept, boxes, outline.camera)
    if not ok.any():
        return None
    m = samples.shape[1]
    r = np.concatenate([samples, samples[:, ::-1]], axis=1)[ok]  # the polygon: lower chain out, upper chain back
    z = np.concatenate([lower, upper[:, ::-1]], axis=1)[ok]
    points = np.concatenate([along[ok][:, None, :] * r[..., None] + outline.probe[:2], z[..., None] + outline.floor_z],
                            axis=2)
    # A run of sections in neighbouring columns is one tube: joined section to section, its ends capped.
    joined = np.r_[np.diff(np.flatnonzero(ok)) == 1, False]
    triangles = _tubes(len(points), 2 * m, joined, m)
    return _welded(points.reshape(-1, 3), triangles)


def _grouped(along: np.ndarray, top: np.ndarray, bottom: np.ndarray, kept: np.ndarray) -> tuple[np.ndarray, ...]:
    """Columns merged in groups of neighbours: their middle azimuth, the widest wedge."""
    n = len(along)
    group = np.arange(n) * _MAX_COLUMNS // n
    size = np.bincount(group)
    mid = np.cumsum(size) - (size + 1) // 2
    widest_top = np.full(_MAX_COLUMNS, -np.inf)
    widest_bottom = np.full(_MAX_COLUMNS, np.inf)
    np.maximum.at(widest_top, group[kept], top[kept])
    np.minimum.at(widest_bottom, group[kept], bottom[kept])
    some = np.bincount(group, kept) > 0
    return along[mid], np.where(some, widest_top, 0.0), np.where(some, widest_bottom, 0.0), some


def _sections(along: np.ndarray, top: np.ndarray, bottom: np.ndarray, kept: np.ndarray, boxes: np.ndarray,
              camera: float) -> tuple[np.ndarray, ...]:
    """Each column's section as r samples (c, m) along the ray from the probe with the heights
    above the floor of its lower and upper chains there (c, m), and whether it has one (c,)."""
    near, far = _reach(along, boxes)  # (c, p) where each ray meets each box's footprint
    height = np.exp(boxes[:, 4])
    # Where the wedge and each box overlap: the wedge's lower ray below the box's top, its upper
    # ray above the floor.
    with np.errstate(divide="ignore", invalid="ignore"):
        below_top = (height[None, :] - camera) / bottom[:, None]
        above_floor = camera / -top
    lo = np.where(bottom[:, None] < 0.0, np.maximum(near, below_top), near)
    hi = np.where(bottom[:, None] > 0.0, np.minimum(far, below_top), far)
    hi = np.where((bottom[:, None] == 0.0) & (camera > height[None, :]), -np.inf, hi)
    hi = np.where(top[:, None] < 0.0, np.minimum(hi, above_floor[:, None]), hi)
    valid = (lo <= hi) & kept[:, None]
    length = np.where(valid, hi - lo, -1.0)
    # The boxes' stretches joined where they touch, else the longest alone.
    start = np.where(valid, lo, np.inf).min(axis=1)
    end = np.where(valid, hi, -np.inf).max(axis=1)
    gap = np.where(valid, lo, -np.inf).max(axis=1) > np.where(valid, hi, np.inf).min(axis=1) + 1e-9
    best = np.argmax(length, axis=1)
    rows = np.arange(len(along))
    start = np.where(gap, lo[rows, best], start)
    end = np.where(gap, hi[rows, best], end)
    ok = valid.any(axis=1)
    start, end = np.where(ok, start, 0.0), np.where(ok, end, 0.0)
    # The samples: both ends, either side of each box's sides (its height steps there), where the
    # lower ray meets the floor and where the upper ray meets each box's top.
    with np.errstate(divide="ignore", invalid="ignore"):
        to_floor = np.where(bottom < 0.0, camera / -bottom, start)
        to_top = np.where(top[:, None] != 0.0, (height[None, :] - camera) / top[:, None], start[:, None])
    sides = np.concatenate([near, far], axis=1)
    candidates = np.concatenate([start[:, None], end[:, None], sides - _STEP, sides + _STEP, to_floor[:, None],
                                 to_top], axis=1)
    candidates = np.where(np.isfinite(candidates), candidates, start[:, None])
    samples = np.sort(np.clip(candidates, start[:, None], end[:, None]), axis=1)
    inside = (samples[:, :, None] >= near[:, None, :] - 1e-12) & (samples[:, :, None] <= far[:, None, :] + 1e-12)
    roof = np.where(inside, height[None, None, :], 0.0).max(axis=2)
    lower = np.maximum(0.0, camera + samples * bottom[:, None])
    upper = np.maximum(np.minimum(roof, camera + samples * top[:, None]), lower)
    return samples, lower, upper, ok


def _reach(along: np.ndarray, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(c, p) the distances from the probe at which each column's ray enters and leaves each
    box's footprint (far < near where it misses)."""
    x, y, log_w, log_d, _, turn = boxes.T
    half = 0.5 * np.exp(np.stack([log_w, log_d], axis=1))  # (p, 2)
    c, s = np.cos(turn), np.sin(turn)
    origin = np.stack([-x * c - y * s, x * s - y * c], axis=1)  # the probe in each box's frame
    local = np.stack([along[:, None, 0] * c + along[:, None, 1] * s, -along[:, None, 0] * s + along[:, None, 1] * c],
                     axis=2)  # (c, p, 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-half - origin) / local
        t2 = (half - origin) / local
    near = np.fmax(np.fmin(t1, t2)[..., 0], np.fmin(t1, t2)[..., 1])
    far = np.fmin(np.fmax(t1, t2)[..., 0], np.fmax(t1, t2)[..., 1])
    return np.maximum(near, 0.0), far


def _tubes(sections: int, ring: int, joined: np.ndarray, chain: int) -> np.ndarray:
    """(t, 3) the triangles of tubes through `sections` rings of `ring` vertices each (ring k's
    vertex i is k * ring + i): ring k joined to ring k + 1 where `joined[k]`, a run's first and
    last rings capped. A ring is an r-monotone polygon: `chain` vertices out along its lower
    chain, then as many back along its upper chain."""
    i = np.arange(ring)
    k = np.flatnonzero(joined)[:, None]
    a, b = k * ring + i, k * ring + (i + 1) % ring
    c, d = a + ring, b + ring
    sides = np.concatenate([np.stack([a, b, d], axis=-1), np.stack([a, d, c], axis=-1)], axis=1).reshape(-1, 3)
    first = np.flatnonzero(np.r_[True, ~joined[:-1]])
    last = np.flatnonzero(~joined)
    j = np.arange(chain - 1)
    # The polygon in strips between consecutive samples: lower j, j + 1 and upper j + 1, j.
    strip = np.stack([np.stack([j, j + 1, ring - 2 - j], axis=-1), np.stack([j, ring - 2 - j, ring - 1 - j], axis=-1)],
                     axis=1).reshape(-1, 3)
    start = (first[:, None, None] * ring + strip[:, ::-1]).reshape(-1, 3)
    end = (last[:, None, None] * ring + strip).reshape(-1, 3)
    return np.concatenate([sides, start, end])


def _welded(points: np.ndarray, triangles: np.ndarray) -> Hull:
    """The mesh with vertices welded on the `_WELD` grid, triangles that lost a corner to a weld
    dropped, and coincident triangles dropped in pairs (a fin of no volume): each leaves every
    edge's count of faces even, so a closed mesh stays closed."""
    grid = np.round(points / _WELD).astype(np.int64)
    unique, ids = np.unique(grid, axis=0, return_inverse=True)
    t = ids.reshape(-1)[triangles]
    t = t[(t[:, 0] != t[:, 1]) & (t[:, 1] != t[:, 2]) & (t[:, 0] != t[:, 2])]
    key = np.sort(t, axis=1)
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    t = t[first[counts.reshape(-1) % 2 == 1]]
    used = np.unique(t)
    remap = np.zeros(len(unique), dtype=np.int64)
    remap[used] = np.arange(len(used))
    return Hull(unique[used] * _WELD, remap[t])


def traced(hull: Hull, outline: Outline) -> np.ndarray:
    """(h, w) the outline's pixels whose centre's ray from the probe meets the hull's mesh (the
    engine's panorama tracer, as a removal sees the proxy)."""
    d = outline.directions
    step = float(np.abs(np.diff(np.arcsin(np.clip(d[:, 0, 2], -1.0, 1.0)))).mean())
    height = round(np.pi / step)
    width = 2 * height
    x, y = project(d[0, 0], width, height, outline.rotation)
    window = (round(float(y)), d.shape[0], round(float(x)) % width, d.shape[1])
    corners = (hull.triangle_corners() - outline.probe) @ outline.rotation.T
    return trace_panorama(corners, width, height, window=window).tri >= 0
