"""Object proxies that are extrusions of a plane polygon: a box, a prism over a clicked footprint,
a box whose top steps along one side (an armchair's seat in front of its back).

An extrusion is a polygon `profile` (k, 2) in the plane of two unit axes u and v through
`origin`, swept along n = u x v over `length`. A prism over a floor footprint has u, v = x, y and
n = z; a stepped box's profile stands upright (u along its depth, v = z) and is swept across its
width. Its mesh is closed, every face's normal outwards.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import polygon
from .meshes import MeshData

_FAR = 1e3  # metres: how far a ray that never meets the floor is followed


@dataclass(frozen=True)
class Solid:
    """The polygon `profile` (k, 2) in metres along `axes[0]` and `axes[1]` from `origin` (3,),
    swept along `axes[2]` (their cross product) over `length` metres."""

    profile: np.ndarray
    origin: np.ndarray
    axes: np.ndarray
    length: float

    @classmethod
    def prism(cls, footprint: np.ndarray, floor_z: float, height: float) -> Solid:
        """A vertical prism: the floor polygon `footprint` (k, 2, world xy) raised `height` from the floor."""
        return cls(np.asarray(footprint, dtype=np.float64), np.array([0.0, 0.0, floor_z]), np.eye(3), float(height))

    def vertices(self) -> np.ndarray:
        """(2k, 3) world vertices: the profile at the sweep's start, then at its end."""
        ring = self._ring()
        start = self.origin + ring[:, :1] * self.axes[0] + ring[:, 1:] * self.axes[1]
        return np.concatenate([start, start + self.length * self.axes[2]])

    def faces(self) -> tuple[tuple[int, ...], ...]:
        k = len(self.profile)
        # The ring runs counter-clockwise about the sweep: the end cap in its order faces along
        # the sweep, the start cap reversed against it, side i from edge i outwards.
        sides = tuple((i, (i + 1) % k, k + (i + 1) % k, k + i) for i in range(k))
        return (tuple(reversed(range(k))), tuple(range(k, 2 * k)), *sides)

    def mesh(self, name: str) -> MeshData:
        return MeshData(name, self.vertices(), self.faces())

    def edges(self) -> np.ndarray:
        """(3k, 2, 3) every edge of the mesh: both caps' rings and the sweep's."""
        v = self.vertices()
        k = len(self.profile)
        ring = np.arange(k)
        pairs = np.concatenate([np.stack([ring, np.roll(ring, -1)], 1), np.stack([ring, np.roll(ring, -1)], 1) + k,
                                np.stack([ring, ring + k], 1)])
        return v[pairs]

    def _ring(self) -> np.ndarray:
        return self.profile if polygon.signed_area(self.profile) > 0.0 else self.profile[::-1]


def inside_polygon(points: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(...,) whether each of `points` (..., 2) lies inside the simple polygon `corners` (k, 2)
    (even-odd rule)."""
    p = np.asarray(points, dtype=np.float64)[..., None, :] - corners
    q = np.asarray(points, dtype=np.float64)[..., None, :] - np.roll(corners, -1, axis=0)
    straddles = (p[..., 1] > 0.0) != (q[..., 1] > 0.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        x = p[..., 0] - p[..., 1] * (q[..., 0] - p[..., 0]) / (q[..., 1] - p[..., 1])
    return np.count_nonzero(straddles & (x > 0.0), axis=-1) % 2 == 1


def prism_silhouette(footprint: np.ndarray, height: float, directions: np.ndarray, camera: float) -> np.ndarray:
    """(h, w) bool: the rays `directions` (h, w, 3) from the probe that meet the vertical prism of
    `height` over `footprint` ((k, 2) from the probe), its bottom `camera` below the probe."""
    d = directions
    dz = d[..., 2]
    # The stretch of each ray between the prism's bottom and top planes, as ray lengths.
    with np.errstate(divide="ignore", invalid="ignore"):
        to_bottom = np.where(dz < 0.0, camera / -dz, _FAR)
        to_top = np.where(dz != 0.0, (height - camera) / dz, _FAR)
    # Down a ray enters through the top (or starts inside) and leaves through the bottom; up it
    # starts inside, below the top, and leaves through the top; level it stays at the probe's height.
    near = np.where(dz < 0.0, np.maximum(to_top, 0.0), 0.0)
    far = np.where(dz < 0.0, to_bottom, to_top)
    ok = (far >= near) & ((dz != 0.0) | (camera <= height))
    a, b = near[..., None] * d[..., :2], far[..., None] * d[..., :2]
    return ok & (inside_polygon(a, footprint) | _crosses(a, b, footprint))


def _crosses(a: np.ndarray, b: np.ndarray, corners: np.ndarray) -> np.ndarray:
    """(...,) whether the segments a-b (..., 2) cross any edge of the polygon `corners` (k, 2)."""
    c, e = corners, np.roll(corners, -1, axis=0) - corners
    r = (b - a)[..., None, :]
    s = a[..., None, :] - c
    den = _cross(r, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = _cross(e, s) / den  # along the segment (s = a - c: a + t r = c + u e)
        u = _cross(r, s) / den  # along the edge
    return np.any((den != 0.0) & (t >= 0.0) & (t <= 1.0) & (u >= 0.0) & (u <= 1.0), axis=-1)


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
