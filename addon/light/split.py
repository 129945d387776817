"""Patches that send through sub-triangles where their light varies within them.

Near the removed object a patch's radiosity can vary within it: dark under the object and lit
beside it, or changed at one end by the removal and not at the other. Spread evenly over the
patch, it would light a receiver beside one end as if the other end's light were there too (a
vertex at the wall's base 0.85 m from a crate saw the floor patch that runs under the crate
with form factor 0.37, and took the revealed footprint's new light as its own). A split patch
sends its photographed radiosity and its first change through its k^2 sub-triangles wherever
pixels take their light; the patch itself carries only the later bounces, which are smooth.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..geometry.patches import split_triangles
from .transport import Senders, make_senders


@dataclass(frozen=True)
class Split:
    """Sub-triangles of split patches, with their light and, once the propagation has computed
    it (`with_transport`), their transport to the coarse receivers."""

    parent: np.ndarray  # (M,) patch of each sub-triangle
    senders: Senders  # (M,) the sub-triangles, sampled at their centroids
    b: np.ndarray  # (M, 3) radiosity as photographed
    db: np.ndarray  # (M, 3) first change of radiosity after removal
    areas: np.ndarray  # (M,)
    t_with: np.ndarray | None = None  # (R, M) the coarse receivers' transport from them
    t_without: np.ndarray | None = None  # (R, M) likewise, without the object

    @classmethod
    def of(cls, triangles: np.ndarray, normals: np.ndarray, areas: np.ndarray,
           groups: list[tuple[np.ndarray, int, np.ndarray, np.ndarray]]) -> Split:
        """Patches (triangles (P, 3, 3), normals (P, 3), areas (P,)) split by groups: patch
        indices (n,), level k, and the radiosity as photographed and its first change at the
        centroids of their k^2 sub-triangles (each (n, k^2, 3), in `split_triangles` order)."""
        groups = [(np.zeros(0, dtype=np.int64), 1, np.zeros((0, 1, 3)), np.zeros((0, 1, 3))), *groups]
        tris = np.concatenate([split_triangles(triangles[g[0]], g[1]).reshape(-1, 3, 3) for g in groups])
        parent = np.concatenate([np.repeat(g[0], g[1] ** 2) for g in groups])
        b = np.concatenate([g[2].reshape(-1, 3) for g in groups])
        db = np.concatenate([g[3].reshape(-1, 3) for g in groups])
        sub_areas = np.concatenate([np.repeat(areas[g[0]], g[1] ** 2) / g[1] ** 2 for g in groups])
        m = len(tris)
        senders = make_senders(tris, normals[parent], b, np.zeros(m, dtype=bool),
                               [(np.arange(m), tris.mean(axis=1)[:, None, :])])
        return cls(parent, senders, b, db, sub_areas)

    def with_transport(self, t_with: np.ndarray, t_without: np.ndarray) -> Split:
        """This split with the coarse receivers' transport from its sub-triangles, (R, M) each."""
        return replace(self, t_with=t_with, t_without=t_without)

    def rest(self, b: np.ndarray) -> np.ndarray:
        """(P, 3) patch radiosities b less what the split patches send through their sub-triangles."""
        out = b.copy()
        out[self.parent] = 0.0
        return out
