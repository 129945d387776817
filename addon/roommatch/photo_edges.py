"""How far the room's reprojected edges lie from the photograph's edges, in pixels.

Each proxy edge is sampled along its reprojection (a curve in lat-long); at each sample the
photograph's log-luminance is read across the curve, and the strongest change within `search`
pixels is where the photograph's edge is. Samples near the edge's ends (where other edges meet)
and those where the photograph shows no clear edge (furniture in front, a plain corner) are left
out; an edge's offset is the median over the rest.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..geometry.resample import resample_axis
from .fit import RoomFit
from .meshes import room_edges
from .projection import pixel_offsets, project

_LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
_STEP = 0.25  # pixels between profile samples across the curve
_END_GAP = 8.0  # pixels left out at each end of an edge
_CONTRAST = 0.04  # the least change of log-luminance per pixel that is an edge
_EDGE_KINDS = ("floor", "ceiling", "corner")


@dataclass(frozen=True)
class EdgeOffsets:
    """Per proxy edge (in `meshes.room_edges` order): the median distance (pixels, at the
    measured width) from the photograph's edge, NaN where too few samples show one, and the share
    of samples that do."""

    width: int
    offsets: np.ndarray
    shown: np.ndarray

    def kinds(self) -> list[str]:
        n = len(self.offsets) // 3
        return [f"{kind} {i}" for kind in _EDGE_KINDS for i in range(n)]

    def summary(self) -> dict[str, Any]:
        return {"measured_width": self.width,
                "edge_offsets_px": {k: (None if np.isnan(v) else round(float(v), 2))
                                    for k, v in zip(self.kinds(), self.offsets, strict=True)}}


def edge_offsets(panorama: np.ndarray, room: RoomFit, *, rotation: np.ndarray | None = None, width: int = 1024,
                 search: float = 6.0, min_shown: float = 0.3) -> EdgeOffsets:
    """Offsets of `room`'s edges from the edges of `panorama` (H, W, 3) linear RGB, top row
    first, measured at `width` x `width` / 2."""
    log = log_luminance(panorama, width)
    offsets, shown = [], []
    for a, b in room_edges(room) - room.probe:
        found = edge_samples(log, a, b, rotation, search).offsets
        shown.append(float(np.mean(~np.isnan(found))) if found.size else 0.0)
        ok = found[~np.isnan(found)]
        offsets.append(float(np.median(np.abs(ok))) if found.size and ok.size >= min_shown * found.size else np.nan)
    return EdgeOffsets(width=width, offsets=np.array(offsets), shown=np.array(shown))


def log_luminance(panorama: np.ndarray, width: int) -> np.ndarray:
    """(width / 2, width) blurred log-luminance of `panorama` resampled to `width` wide."""
    image = np.asarray(panorama, dtype=np.float32)
    image = resample_axis(resample_axis(image, width // 2, axis=0), width, axis=1)
    return _blur(np.log(np.maximum(image @ _LUMINANCE.astype(np.float32), 1e-4)).astype(np.float64))


@dataclass(frozen=True)
class EdgeSamples:
    """Samples along a reprojected edge, a pixel apart: their pixel coordinates (n, 2), unit
    normals across the curve (n, 2), and the signed offset along the normal of the strongest
    change of log-luminance (NaN where there is none)."""

    points: np.ndarray
    normals: np.ndarray
    offsets: np.ndarray

    def found(self) -> np.ndarray:
        """(m, 2) where the photograph's edge is, at the samples that show one."""
        ok = ~np.isnan(self.offsets)
        return self.points[ok] + self.offsets[ok, None] * self.normals[ok]


def edge_samples(log: np.ndarray, a: np.ndarray, b: np.ndarray, rotation: np.ndarray | None,
                 search: float) -> EdgeSamples:
    """Look for the photograph's edge across the reprojection of the segment a-b (probe frame)
    within `search` pixels of `log` (from `log_luminance`)."""
    height, width = log.shape
    dense = project(a + np.linspace(0.0, 1.0, 2001)[:, None] * (b - a), width, height, rotation)
    steps = np.linalg.norm(pixel_offsets(dense[1:], dense[:-1], width), axis=1)
    along = np.concatenate([[0.0], np.cumsum(steps)])
    total = along[-1]
    if total < 2 * _END_GAP + 2:
        return EdgeSamples(np.empty((0, 2)), np.empty((0, 2)), np.empty(0))
    at = np.arange(_END_GAP, total - _END_GAP, 1.0)
    index = np.clip(np.searchsorted(along, at), 1, len(dense) - 1)
    points = dense[index]
    tangent = pixel_offsets(dense[np.minimum(index + 1, len(dense) - 1)], dense[index - 1], width)
    tangent /= np.maximum(np.linalg.norm(tangent, axis=1, keepdims=True), 1e-12)
    normal = np.stack([-tangent[:, 1], tangent[:, 0]], axis=1)
    s = np.arange(-search - 1.0, search + 1.0 + 1e-9, _STEP)
    xy = points[:, None, :] + s[None, :, None] * normal[:, None, :]
    profile = _bilinear(log, xy[..., 0], xy[..., 1])
    change = np.abs(np.gradient(profile, _STEP, axis=1))
    inside = np.abs(s) <= search
    change = np.where(inside[None, :], change, -1.0)
    best = np.argmax(change, axis=1)
    rows = np.arange(len(best))
    strength = change[rows, best]
    # Sub-sample peak by a parabola through the best sample and its neighbours.
    lo, hi = change[rows, best - 1], change[rows, np.minimum(best + 1, len(s) - 1)]
    curvature = lo - 2 * strength + hi
    shift = np.where(curvature < 0, 0.5 * (lo - hi) / np.where(curvature < 0, curvature, 1.0), 0.0)
    offset = s[best] + np.clip(shift, -0.5, 0.5) * _STEP
    on_edge = (strength >= _CONTRAST) & (points[:, 1] > 1) & (points[:, 1] < height - 2)
    return EdgeSamples(points, normal, np.where(on_edge, offset, np.nan))


def _bilinear(image: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """`image` at pixel coordinates (x, y), centres at whole numbers; wraps in x, clamps in y."""
    height, width = image.shape
    y = np.clip(y, 0.0, height - 1.0)
    x0, y0 = np.floor(x).astype(np.int64), np.minimum(np.floor(y).astype(np.int64), height - 2)
    fx, fy = x - x0, y - y0
    x0, x1 = np.mod(x0, width), np.mod(x0 + 1, width)
    top = image[y0, x0] * (1 - fx) + image[y0, x1] * fx
    bottom = image[y0 + 1, x0] * (1 - fx) + image[y0 + 1, x1] * fx
    return top * (1 - fy) + bottom * fy


def _blur(image: np.ndarray) -> np.ndarray:
    """A 1-2-1 binomial blur along both axes (wrapping in x): noise would make every pixel an edge."""
    rows = np.pad(image, ((1, 1), (0, 0)), mode="edge")
    image = 0.25 * rows[:-2] + 0.5 * rows[1:-1] + 0.25 * rows[2:]
    return 0.25 * np.roll(image, 1, axis=1) + 0.5 * image + 0.25 * np.roll(image, -1, axis=1)
