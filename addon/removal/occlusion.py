"""What blocks light: the removed object and every other occluder, kept apart so that one ray
test gives the transport with the object and without it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry.mesh import Geometry, boundary_objects
from ..geometry.occluders import Occluders
from ..geometry.solid import in_frame, principal_frame
from ..light.transport import Senders, transport
from ..report import Report
from .target import Target
from .trace import Traced

_DETAILED = 1000  # triangles beyond which an object's box stands for its vertices as witnesses


@dataclass(frozen=True)
class Occlusion:
    removed: Occluders  # the object's triangles
    others: Occluders | None  # every other object that can cast a shadow (not the room's boundary)

    def transport(self, points: np.ndarray, normals: np.ndarray, senders: Senders,
                  callbacks: RunCallbacks) -> tuple[np.ndarray, np.ndarray]:
        """(T, T') (R, S) from the senders to receivers (R, 3) with normals (R, 3)."""
        return transport(points, normals, senders, self.removed, self.others, callbacks.check)

    def transport_without(self, points: np.ndarray, normals: np.ndarray, senders: Senders,
                          callbacks: RunCallbacks) -> np.ndarray:
        """T' (R, S) as `transport` gives it, with no ray tested against the object (T' never
        meets it)."""
        return transport(points, normals, senders, None, self.others, callbacks.check)[1]

    def seen(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N,) whether the probe (the origin) sees each point past the removed object, and
        (N,) whether it sees it at all."""
        probe = np.zeros_like(points)
        past_object = ~self.removed.blocked(probe, points)
        if self.others is None:
            return past_object, past_object
        return past_object, past_object & ~self.others.blocked(probe, points)


def occluders(geo: Geometry, target: Target, traced: Traced, rep: Report) -> Occlusion:
    """The occluders. An object that bounds the room (the probe and every vertex of what it
    sees, or the corners of a detailed object's box, lie on the lit side of all its triangles:
    the shell, a flat wall or floor) can never block a segment inside it and is left out: it is
    most of the triangles a ray would meet."""
    seen = np.unique(traced.obj_h)
    witnesses = np.concatenate([*(_witnesses(geo.triangles[geo.tri_object == k]) for k in seen), np.zeros((1, 3))])
    bound = boundary_objects(geo, witnesses)
    on_target = geo.tri_object == target.index
    removed = Occluders(geo.triangles[on_target], geo.tri_object[on_target], target.eps)
    other = ~on_target & ~bound[geo.tri_object]
    others = Occluders(geo.triangles[other], geo.tri_object[other], target.eps) if other.any() else None
    rep.info["occluder_objects"] = [geo.object_names[k] for k in np.unique(geo.tri_object[other])]
    return Occlusion(removed, others)


def _witnesses(triangles: np.ndarray) -> np.ndarray:
    """Points whose lying on the lit side of a plane shows that all of the object's do: its
    vertices, or for a detailed object the 8 corners of its box in its own frame (a half-space
    holding them holds the box)."""
    if len(triangles) <= _DETAILED:
        return triangles.reshape(-1, 3)
    frame = principal_frame(triangles)
    framed = in_frame(triangles.reshape(-1, 3), frame)
    lo, hi = framed.min(axis=0), framed.max(axis=0)
    corners = np.array([[(lo, hi)[(i >> a) & 1][a] for a in range(3)] for i in range(8)])
    return in_frame(corners, frame.T)
