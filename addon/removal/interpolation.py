"""Lattice vertices as receivers, and values interpolated from them to points."""
from __future__ import annotations

import numpy as np


def inset(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Lattice points moved a hair into their triangle: a receiver exactly on the edge between
    floor and wall sees the wall edge-on (form factor 0) while a receiver 1 mm away sees it
    fill half its hemisphere; the pixels the lattice stands for are all inside."""
    return points + 1e-3 * (tris.mean(axis=1) - points)


def interpolate(values: np.ndarray, corners: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """(N, C) the weighted sum over each point's corners (N, K) of `values` (V, C)."""
    return np.einsum("nk,nkc->nc", weights, values[corners])
