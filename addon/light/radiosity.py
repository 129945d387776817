"""Patch radiosity from the panorama, reflectance recovery, and propagation of a change.

B = pi L for Lambertian patches; a patch's B is pi times the area-weighted mean radiance of the
panorama pixels that see it. Reflectance is rho = B / E (thesis 3.4), guarded where E -> 0 and
clamped below 1; a patch far brighter than the light it receives is an emitter. The change of
radiosity after a removal is shot around the room for as many bounces as it matters
(progressive refinement of dB, Cohen et al. 1988).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

LUMA = np.array([0.2126, 0.7152, 0.0722])
RHO_MAX = 0.99
EMITTER_RHO = 1.5  # luminance ratio B/E above which a patch is a light source, not a reflector


def patch_radiosity(
    radiance: np.ndarray, patch: np.ndarray, weight: np.ndarray, areas: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """(P, 3) radiosity and (P,) visible area fraction of patches from the pixels that see them.

    radiance (N, 3), patch (N,) patch index of each pixel, weight (N,) the surface area the pixel
    covers (so the mean is over area, not over pixels).
    """
    n = len(areas)
    seen_area = np.bincount(patch, weight, minlength=n)
    b = np.stack([np.bincount(patch, weight * radiance[:, c], minlength=n) for c in range(3)], axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        b = np.where(seen_area[:, None] > 0.0, np.pi * b / seen_area[:, None], 0.0)
    return b, np.minimum(seen_area / np.maximum(areas, 1e-300), 1.0)


@dataclass
class Reflectance:
    rho: np.ndarray  # (P, 3), 0 for emitters
    emitter: np.ndarray  # (P,) bool
    clamped: int  # patches whose rho was clamped below 1
    guarded: int  # patches with E ~ 0 whose rho could not be measured


def recover_reflectance(
    b: np.ndarray, e: np.ndarray, visible: np.ndarray, e_floor: float, *, e_test: np.ndarray | None = None
) -> Reflectance:
    """rho = B / E for visible patches; emitters detected (B above EMITTER_RHO times `e_test`,
    the luminance of E, by default that of `e`); E below `e_floor` guarded."""
    b_luma, e_luma = b @ LUMA, e @ LUMA
    dark = e_luma <= e_floor
    emitter = visible & (b_luma > EMITTER_RHO * np.maximum(e_luma if e_test is None else e_test, e_floor))
    with np.errstate(invalid="ignore", divide="ignore"):
        rho = np.where(e > e_floor, b / np.where(e > e_floor, e, 1.0), 0.0)
    over = visible & ~emitter & (rho >= RHO_MAX).any(axis=1)
    rho = np.clip(rho, 0.0, RHO_MAX)
    rho[emitter] = 0.0
    return Reflectance(rho=rho, emitter=emitter, clamped=int(over.sum()),
                       guarded=int((visible & dark & ~emitter).sum()))


def fill_unseen(rho: np.ndarray, measured: np.ndarray, groups: list[np.ndarray], areas: np.ndarray) -> np.ndarray:
    """Reflectance for patches not measured: the area-weighted mean of the first group (the same
    surface, then the same object, ...) that has measured patches, else the global median."""
    out = rho.copy()
    todo = ~measured
    fallback = np.median(rho[measured], axis=0) if measured.any() else np.full(3, 0.5)
    for key in groups:
        if not todo.any():
            break
        ok = measured & (key >= 0)
        group = np.where(key >= 0, key, 0)
        size = int(group.max()) + 1 if len(group) else 1
        area_sum = np.bincount(group[ok], areas[ok], minlength=size)
        mean = np.stack([np.bincount(group[ok], areas[ok] * rho[ok, c], minlength=size) for c in range(3)], axis=1)
        has = area_sum > 0.0
        mean = mean / np.where(has, area_sum, 1.0)[:, None]
        take = todo & (key >= 0) & has[group]
        out[take] = mean[group[take]]
        todo &= ~take
    out[todo] = fallback
    return out


def propagate(
    db1: np.ndarray, rho: np.ndarray, areas: np.ndarray, gather: Callable[[np.ndarray], np.ndarray], *,
    tolerance: float, max_bounces: int
) -> tuple[np.ndarray, int]:
    """Total change sum_k dB_k of radiosity, dB_{k+1} = rho * gather(dB_k), and the bounces used.

    gather(dB) -> (P, 3) irradiance change at the patches; stops when a bounce adds less than
    `tolerance` of the first change's power (luminance times area); when `max_bounces` stops it
    first, the rest of the series is added as a geometric tail.
    """
    def power(db: np.ndarray) -> float:
        return float((np.abs(db) @ LUMA * areas).sum())

    total = db1.copy()
    current = db1
    first = power(db1)
    previous = first
    bounces = 0
    while bounces < max_bounces and first > 0.0:
        current = rho * gather(current)
        bounces += 1
        total += current
        now = power(current)
        if now <= tolerance * first:
            return total, bounces
        ratio, previous = now / max(previous, 1e-300), now
    if bounces and first > 0.0 and ratio < 1.0:
        # Cohen's ambient term: the bounces not shot form a geometric series of the last one.
        total += current * (ratio / (1.0 - ratio))
    return total, bounces
