"""What the removed object hid from the probe: reflectance synthesised on the plane, lit anew.

Reflectance, not radiance, is synthesised (DESIGN 3.6): rho = pi L / E carries no shadow, so the
shadow gradients around the object cannot leak into the fill, and the filled floor is then lit
by the irradiance after the removal, L' = rho E' / pi. Synthesis runs on a rectified raster of
the revealed plane (`planeraster`), the exemplar being the same surface's visible cells around
the hole.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..geometry import planeraster as PR
from ..errors import Cancelled, DimredError
from .texture import SynthesisParams, fill

_MAX_CELLS = 512 * 512  # bounds the raster (and the exemplar) whatever the panorama size
_DEPTH_TOLERANCE = 0.02  # relative: a cell is where a ray meets its surface within this
_MIN_KNOWN = 64  # visible cells a surface needs to serve as its own exemplar


@dataclass
class PanoramaMaps:
    """(H, W) per pixel: the surface id and distance of the first hit with the object and
    without it (-1 where nothing is hit), and whether the object is the first hit."""

    surface_with: np.ndarray
    distance_with: np.ndarray
    surface_without: np.ndarray
    distance_without: np.ndarray
    hidden: np.ndarray


@dataclass
class SurfaceFill:
    rho: np.ndarray  # (N, 3) reflectance at the hidden points
    raster_shape: tuple[int, int]
    cell: float
    known_cells: int
    hole_cells: int
    synthesised: bool  # False: too little of the surface is seen; its mean reflectance is used


def fill_surface(
    maps: PanoramaMaps,
    rho_image: np.ndarray,
    rho_valid: np.ndarray,
    surface: int,
    normal: np.ndarray,
    points: np.ndarray,
    cell: float,
    margin: float,
    params: SynthesisParams,
    seed: int = 0,
    cancel: Callable[[], bool] | None = None,
    progress: Callable[[np.ndarray], None] | None = None,
    along: np.ndarray | None = None,
) -> SurfaceFill:
    """Reflectance at the hidden `points` (N, 3) of one plane, synthesised on a raster with cells
    of about `cell` covering them and `margin` times their extent around, from the panorama's
    reflectance `rho_image` (H, W, 3) where `rho_valid`; the raster's axes follow `along` on a
    floor or ceiling (`planeraster.plane_axes`). `progress(rho)` gets the (N, 3)
    reflectance at `points` after each synthesis level, coarsest first."""
    raster = PR.build_raster(normal, points, cell, margin, _MAX_CELLS, along)
    flags = PR.classify(raster, maps.surface_with, maps.distance_with, maps.surface_without,
                        maps.distance_without, maps.hidden, surface, _DEPTH_TOLERANCE)
    values, weight = PR.sample_panorama(raster, rho_image, rho_valid & (maps.surface_with == surface))
    known = (flags == PR.SEEN) & (weight > 0.5)
    # The hidden points are looked up bilinearly: fill the cells around each as well.
    r, c = (np.floor(x).astype(np.int64) for x in raster.coords(points))
    hole = np.zeros(raster.shape, dtype=bool)
    h, w = raster.shape
    for dr in (0, 1):
        for dc in (0, 1):
            hole[np.clip(r + dr, 0, h - 1), np.clip(c + dc, 0, w - 1)] = True
    hole |= flags == PR.HIDDEN
    hole &= ~known
    mean = values[known].mean(axis=0) if known.any() else np.zeros(3)
    image = np.where(known[..., None], values, mean)
    synthesised = False
    if known.sum() >= _MIN_KNOWN:
        on_level = None if progress is None else (
            lambda _level, preview: progress(PR.sample_raster(raster, preview, points)))
        try:
            image = fill(image, known, hole, params, seed=seed, progress=on_level, cancel=cancel)
            synthesised = True
        except Cancelled:
            raise
        except DimredError:
            pass  # too little exemplar: the mean below is the honest fallback, reported by the caller
    rho = PR.sample_raster(raster, image, points)
    return SurfaceFill(rho=rho, raster_shape=raster.shape, cell=raster.cell, known_cells=int(known.sum()),
                       hole_cells=int(hole.sum()), synthesised=synthesised)
