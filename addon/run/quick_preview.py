"""A first look at a removal within a fraction of a second of its start (no bpy).

The engine's own previews come after its lighting solve, seconds or minutes into a run. This
one needs only a small copy of the panorama and the object's triangles: the pixels that show
the object are filled from the pixels around them (push-pull: average down a pyramid until no
cell is empty, then interpolate back up), a plausible "object gone" before the engine puts the
light and the texture right. The object's shadow stays and surfaces in front of the object are
filled with it: the engine's previews correct both.

Small triangles are splatted, not traced: points spaced at most half a pixel apart over each
mark the pixels they land in. Tracing a 50k-triangle object takes a second at any size, as
the tracer's cost is per triangle; splatting it takes milliseconds. Triangles that span more
than a few pixels, few in any mesh, are traced (a splat would need far too many points where
they reach towards a pole, whose rows' pixels narrow to nothing).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import latlong
from ..geometry.raycast import trace_panorama
from .small_copy import resample

# Triangles needing more steps along their edges than this are traced instead of splatted.
_SPLAT_STEPS = 8
# Splat points per batch: bounds the memory of a batch.
_BATCH_POINTS = 1 << 20


@dataclass(frozen=True)
class QuickFill:
    hole: np.ndarray  # (h, w) bool: the pixels filled, the object's silhouette and a margin
    difference: np.ndarray  # (h, w, 3) float32: fill - panorama in the hole, 0 elsewhere


def quick_difference(panorama: np.ndarray, triangles: np.ndarray, *, margin: int = 1) -> QuickFill:
    """The difference that fills where the object shows in `panorama` (h, w, 3) from its
    surroundings. `triangles` (T, 3, 3): the object in the probe frame (the probe centre at the
    origin, the panorama's axes); `margin` pixels around its silhouette are filled too, as a
    small copy blends the object's edge into them."""
    height, width = panorama.shape[:2]
    hole = latlong.dilate(silhouette(triangles, width, height), margin)
    difference = np.zeros((height, width, 3), dtype=np.float32)
    if hole.any() and not hole.all():
        difference[hole] = (push_pull(panorama, ~hole) - panorama)[hole]
    return QuickFill(hole, difference)


def silhouette(triangles: np.ndarray, width: int, height: int) -> np.ndarray:
    """(height, width) bool: the pixels of a `width` x `height` panorama that the triangles
    (T, 3, 3), seen from the origin, cover."""
    mask = np.zeros((height, width), dtype=bool)
    tris = np.asarray(triangles, dtype=np.float64)
    if not len(tris):
        return mask
    steps = _steps(tris, width, height)
    large = steps > _SPLAT_STEPS
    if large.any():
        mask |= trace_panorama(tris[large], width, height).tri >= 0
    # The others in buckets of step counts a factor 2^(1/4) apart (at most 1.4 times the points
    # each needs), one lattice per bucket.
    small = tris[~large]
    buckets = np.ceil(4.0 * np.log2(steps[~large])).astype(np.int64)
    for k in np.unique(buckets):
        members = small[buckets == k]
        n = int(np.ceil(2.0 ** (k / 4.0)))
        i, j = np.nonzero(np.add.outer(np.arange(n + 1), np.arange(n + 1)) <= n)
        s, t = i / n, j / n
        per = max(1, _BATCH_POINTS // len(s))
        for start in range(0, len(members), per):
            batch = members[start:start + per]
            a, ab, ac = batch[:, None, 0], (batch[:, 1] - batch[:, 0])[:, None], (batch[:, 2] - batch[:, 0])[:, None]
            points = a + s[None, :, None] * ab + t[None, :, None] * ac
            rows, cols = latlong.uv_to_pixel(*latlong.direction_to_uv(points), width, height)
            mask[rows, cols] = True
    return mask


def _steps(tris: np.ndarray, width: int, height: int) -> np.ndarray:
    """Steps along each triangle's edges that space its lattice at most half a pixel apart."""
    unit = tris / np.linalg.norm(tris, axis=2, keepdims=True)
    chord = np.linalg.norm(unit[:, [1, 2, 0]] - unit, axis=2).max(axis=1)
    angle = 2.0 * np.arcsin(np.minimum(0.5 * chord, 1.0))
    # Columns narrow towards the poles: a pixel spans 2 pi sin(polar angle) / width there. No
    # point of a triangle is farther from all its corners than its longest edge, so none is
    # nearer a pole than its nearest corner less that edge.
    from_pole = np.arctan2(np.linalg.norm(unit[..., :2], axis=2), np.abs(unit[..., 2])).min(axis=1)
    sine = np.sin(np.clip(from_pole - angle, 1.0 / width, 0.5 * np.pi))
    pixel = np.minimum(np.pi / height, 2.0 * np.pi * sine / width)
    return np.maximum(np.ceil(2.0 * angle / pixel), 1.0)


def push_pull(image: np.ndarray, known: np.ndarray) -> np.ndarray:
    """(h, w, C) float32 `image` with the pixels where `known` (h, w) is False filled smoothly
    from the known ones."""
    if not known.any():
        raise ValueError("push_pull needs at least one known pixel to fill from")
    weight = known.astype(np.float32)[..., None]
    value = np.asarray(image, dtype=np.float32) * weight
    levels = [(value, weight)]
    while not (weight > 0).all():
        value, weight = _halve(value), _halve(weight)
        levels.append((value, weight))
    filled = value / weight
    for value, weight in reversed(levels[:-1]):
        coarse = resample(filled, *value.shape[:2])
        filled = np.where(weight > 0, value / np.maximum(weight, 1e-30), coarse)
    return filled


def _halve(image: np.ndarray) -> np.ndarray:
    """2 x 2 sums (an odd last row repeats, an odd last column wraps to the first)."""
    if image.shape[0] > 1:
        if image.shape[0] % 2:
            image = np.concatenate([image, image[-1:]], axis=0)
        image = image[0::2] + image[1::2]
    if image.shape[1] > 1:
        if image.shape[1] % 2:
            image = np.concatenate([image, image[:, :1]], axis=1)
        image = image[:, 0::2] + image[:, 1::2]
    return image
