"""The object's outline as the photograph shows it: the 0.5 contour of the segmentation's
matte, to a fraction of a pixel, with its normals, in the tangent plane at the object."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import latlong
from ..light.radiosity import LUMA
from ..segmentation.masks import blur
from ..segmentation.seen import SeenObject
from .tangent import TangentPlane


@dataclass(frozen=True)
class Outline:
    """(M, 2) points of the outline in the tangent plane, (M, 2) unit normals into the object,
    and (M,) how sharply the image changes across each (its log luminance, 1.5 px each side)."""

    points: np.ndarray
    normals: np.ndarray
    contrast: np.ndarray


def photographed_outline(seen: SeenObject, plane: TangentPlane) -> Outline:
    """Where the matte crosses 0.5 between neighbouring pixels, inside the band the image
    decided (at the band's edge the cut met the proxy's constraint, not an edge of the image)."""
    seg = seen.segmentation
    alpha = seg.alpha.astype(np.float64)
    inner = seg.band.copy()
    inner[1:] &= seg.band[:-1]
    inner[:-1] &= seg.band[1:]
    inner[:, 1:] &= seg.band[:, :-1]
    inner[:, :-1] &= seg.band[:, 1:]
    grad_r, grad_c = np.gradient(alpha)
    found = []
    for axis in (0, 1):
        lo = alpha[:-1] if axis == 0 else alpha[:, :-1]
        hi = alpha[1:] if axis == 0 else alpha[:, 1:]
        ok = (inner[:-1] & inner[1:]) if axis == 0 else (inner[:, :-1] & inner[:, 1:])
        cross = ok & ((lo - 0.5) * (hi - 0.5) < 0)
        r, c = np.nonzero(cross)
        t = (0.5 - lo[r, c]) / (hi[r, c] - lo[r, c])
        gr = 0.5 * (grad_r[r, c] + (grad_r[r + 1, c] if axis == 0 else grad_r[r, c + 1]))
        gc = 0.5 * (grad_c[r, c] + (grad_c[r + 1, c] if axis == 0 else grad_c[r, c + 1]))
        found.append((r + t * (axis == 0), c + t * (axis == 1), gr, gc))
    rows, cols, gr, gc = (np.concatenate(parts) for parts in zip(*found, strict=True))
    norm = np.hypot(gr, gc)
    keep = norm > 1e-6
    rows, cols, gr, gc, norm = rows[keep], cols[keep], gr[keep], gc[keep], norm[keep]
    nr, nc = gr / norm, gc / norm
    here = plane.project(_directions(seen, rows, cols))
    ahead = plane.project(_directions(seen, rows + 0.25 * nr, cols + 0.25 * nc))
    normals = ahead - here
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    luminance = seen.image.astype(np.float64) @ LUMA
    y = np.log(luminance + 1e-3 * max(float(np.median(luminance)), 1e-30))
    y = blur(y)
    contrast = np.abs(_bilinear(y, rows + 1.5 * nr, cols + 1.5 * nc) - _bilinear(y, rows - 1.5 * nr, cols - 1.5 * nc))
    return Outline(points=here, normals=normals, contrast=contrast)


def _bilinear(a: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """`a` (h, w) at fractional positions, clamped to its edges."""
    h, w = a.shape
    r = np.clip(rows, 0.0, h - 1.0)
    c = np.clip(cols, 0.0, w - 1.0)
    r0 = np.minimum(np.floor(r).astype(np.int64), h - 2) if h > 1 else np.zeros(len(r), dtype=np.int64)
    c0 = np.minimum(np.floor(c).astype(np.int64), w - 2) if w > 1 else np.zeros(len(c), dtype=np.int64)
    fr, fc = r - r0, c - c0
    r1, c1 = np.minimum(r0 + 1, h - 1), np.minimum(c0 + 1, w - 1)
    return ((a[r0, c0] * (1 - fc) + a[r0, c1] * fc) * (1 - fr) + (a[r1, c0] * (1 - fc) + a[r1, c1] * fc) * fr)


def _directions(seen: SeenObject, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Directions through fractional (row, column) positions of the window (0 = a pixel's centre)."""
    f = seen.frame
    return latlong.pixel_directions_at(f.row0 + rows, f.col0 + cols, f.width, f.height)
