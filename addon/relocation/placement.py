"""Where a move under the fixed-view constraint puts the object, and whether it may go there.

The object must keep standing on its support plane, may not cut through or sit inside another
object or a wall, and may not enclose the probe; each refusal names its reason.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DimredError
from ..geometry import solid
from ..geometry.occluders import Occluders
from ..geometry.raycast import crossings, first_hits
from ..scene import SceneData
from . import fixedview
from .fixedview import Move

_SUPPORT_GAP = 0.02  # of the object's height: a foot this close above a surface stands on it


@dataclass
class Placement:
    """Where the move puts the object (world space), and what it stands on."""

    matrix: np.ndarray  # (4, 4) the move
    triangles: np.ndarray  # (T, 3, 3) the scene's triangles with the object moved
    support: list[str]  # the objects it stands on at the new place
    elevation_change: float  # degrees, see fixedview.elevation_change


def place(scene: SceneData, target: int, move: Move) -> Placement:
    """The object moved by `move`, or a DimredError when the new place breaks the constraint:
    the object would not stand on its support plane, would cut through or sit inside another
    object or a wall, or would enclose the probe."""
    rows = scene.tri_object == target
    tris = np.asarray(scene.triangles, dtype=np.float64)
    obj = tris[rows]
    name = scene.object_names[target]
    reference = fixedview.reference_point(obj)
    matrix = fixedview.move_matrix(scene.center, reference, move)
    moved = tris.copy()
    moved[rows] = fixedview.apply(matrix, obj)
    others = _Others(tris[~rows], np.asarray(scene.tri_object)[~rows], scene.object_names)
    pts = obj.reshape(-1, 3)
    size = float(np.linalg.norm(pts.max(axis=0) - pts.min(axis=0)))
    height = float(np.ptp(pts[:, 2]))
    scene_size = float(np.ptp(tris.reshape(-1, 3), axis=0).max())
    # A foot stands on a surface within `gap` above or below it: proxies are modelled by hand,
    # sunk into the floor a little or floating above it.
    gap = _SUPPORT_GAP * max(height, size * 1e-2)
    support = _support_at_new_place(name, pts, height, gap, matrix, others)

    new_pts = moved[rows].reshape(-1, 3)
    centre = np.asarray(scene.center, dtype=np.float64)
    if np.all(new_pts.min(axis=0) < centre) and np.all(new_pts.max(axis=0) > centre):
        raise DimredError(f"at the new place '{name}' would enclose the probe centre")
    # The object's bottom, lifted by the gap, may touch nothing (the support included: a foot
    # inside a cabinet finds the cabinet's bottom below it, but that is no support).
    floor_z = pts[:, 2].min() + gap
    lifted = [t.copy() for t in (obj, moved[rows])]
    for t in lifted:
        t[..., 2] = np.maximum(t[..., 2], floor_z)
    collided = _collisions(*lifted, others.triangles, others.ids, 1e-6 * max(scene_size, 1e-9))
    if collided:
        raise DimredError(f"at the new place '{name}' would cut through {others.listed(collided)}")
    return Placement(matrix, moved, support, fixedview.elevation_change(scene.center, reference, move))


@dataclass
class _Others:
    """The scene's triangles other than the object's, with their objects' indices and the names."""

    triangles: np.ndarray  # (T, 3, 3)
    ids: np.ndarray  # (T,) object index of each triangle
    names: list[str]  # the scene's object names, by index

    def listed(self, objects) -> str:
        return ", ".join(repr(self.names[k]) for k in objects)


def _support_at_new_place(name: str, pts: np.ndarray, height: float, gap: float, matrix: np.ndarray,
                          others: _Others) -> list[str]:
    """The objects the object's feet (its lowest points `pts`) stand on after the move `matrix`,
    or a DimredError when it stands on nothing now or would not stand on its support plane there."""
    feet = np.unique(pts[pts[:, 2] <= pts[:, 2].min() + 1e-2 * max(height, 1e-9)], axis=0)
    down = np.broadcast_to([0.0, 0.0, -1.0], feet.shape)
    hit, t = first_hits(feet + np.array([0.0, 0.0, gap]), down, others.triangles)
    stands = t <= 2.0 * gap
    if not stands.any():
        raise DimredError(
            f"'{name}' does not stand on a surface (nothing within {gap:.3g} of its lowest points): a "
            "relocation keeps an object on its support plane, so model the surface it stands on"
        )
    new_feet = fixedview.apply(matrix, feet[stands])
    hit_new, t_new = first_hits(new_feet + np.array([0.0, 0.0, gap]), down[: len(new_feet)], others.triangles)
    # The support is a plane, not an object: a floor modelled in pieces, or a rug on it, holds
    # the object as well at the same height.
    off = t_new > 2.0 * gap
    if off.any():
        was_on = others.listed(np.unique(others.ids[hit[stands]]))
        below = sorted({others.names[others.ids[k]] for k in hit_new[off] if k >= 0})
        where = f"over {', '.join(repr(n) for n in below)} at another height" if below else "over nothing"
        raise DimredError(
            f"at the new place '{name}' would not stand on its support plane (where {was_on} holds it now): "
            f"{int(off.sum())} of its feet would be {where}. Choose a smaller move"
        )
    return [others.names[k] for k in np.unique(others.ids[hit_new])]


def _collisions(before: np.ndarray, after: np.ndarray, others: np.ndarray, other_ids: np.ndarray,
                eps: float) -> list[int]:
    """Objects that the moved object cuts (its edges cross them) or sits in (its centre inside
    their closed mesh), where its old place did not (a model that already touched a wall a
    little is not refused for that)."""
    found = []
    for k in np.unique(other_ids):
        tris = others[other_ids == k]
        occluders = Occluders(tris, other_ids[other_ids == k], eps)
        # Inside and outside mean something for a closed mesh only (a ceiling with lamp holes
        # is crossed once or not at all, wherever one stands).
        closed = solid.closed(tris, max(eps, 1e-12))
        if _collides(after, tris, occluders, closed=closed) and not _collides(before, tris, occluders, closed=closed):
            found.append(int(k))
    return found


# Not straight up: a box's centre lies under the diagonal its top face's two triangles share,
# and a ray along that edge would count the face twice.
_UP = np.array([[0.0123, 0.0271, 1.0]])


def _collides(obj: np.ndarray, tris: np.ndarray, occluders: Occluders, *, closed: bool) -> bool:
    """Whether the object's triangles (n, 3, 3) cut the other object `tris` (its edges cross it)
    or sit inside it (its centre inside a closed mesh)."""
    edge_starts = obj.reshape(-1, 3)
    edge_ends = np.roll(obj, -1, axis=1).reshape(-1, 3)
    inside = closed and crossings(fixedview.reference_point(obj)[None], _UP, tris)[0] % 2 == 1
    return bool(inside or occluders.blocked(edge_starts, edge_ends).any())


