"""The removed object in the probe-frame geometry, and the scales every later stage takes from it."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DimredError
from ..geometry.mesh import Geometry, build_geometry, plane_of_object, surface_keys
from ..quality import Params
from ..report import Report
from ..scene import SceneData

#: The object's radius spans at least this many shadow cells.
SHADOW_CELLS_PER_RADIUS = 8


@dataclass(frozen=True)
class Target:
    """What is removed, where the relighting may go, and the sizes derived from the object."""

    index: int  # the object's index in the geometry's object names
    planes: tuple[int, ...]  # the only objects to relight (the user's --plane), empty: every surface
    centre: np.ndarray  # (3,) centre of its bounding sphere, probe frame
    radius: float  # radius of its bounding sphere
    fine_cell: float  # cell of the fine lattice near it
    shadow_cell: int  # pixels a cell of its shadows spans (`shadow_cells`), 1: every pixel computed
    eps: float  # length tolerance of the ray tests
    surface_key: np.ndarray  # (T,) the plane each triangle lies in (`geometry.mesh.surface_keys`)


def prepare(scene: SceneData, object_name: str, planes: list[str] | tuple[str, ...], params: Params,
            rep: Report, *, geo: Geometry | None = None) -> tuple[Geometry, Target]:
    """The scene's triangles in the probe frame (`geo` where the caller has built them) and the
    object to remove; DimredError when the object or a --plane is unknown, the object has no
    faces or a --plane is not flat."""
    index = object_index(scene, object_name)
    with rep.stage("geometry"):
        geo = geo if geo is not None else scene_geometry(scene)
        if not (geo.tri_object == index).any():
            raise DimredError(f"'{object_name}' has no faces to remove")
        plane_ids = tuple(_plane_index(geo, name) for name in planes)
        rep.guard("degenerate_triangles_dropped", geo.dropped_degenerate)
    centre, radius = geo.bounding_sphere(index)
    # The fine grid must resolve what the pixels show: the contact shadow where the object
    # touches the floor or a wall is a few centimetres wide, and interpolating it over coarse
    # cells darkens the pixels beside the object (E too low, so the ratio over-brightens).
    height = scene.hdri.shape[0]
    pixel = float(np.linalg.norm(centre)) * np.pi / height
    fine_cell = min(radius / params.fine_cells, params.fine_pixels * pixel)
    # A shadow cell must stay narrower than the object's legs and slats, a tenth of its size or
    # so: an object a few dozen pixels across has every pixel's shadow computed.
    shadow_cell = int(np.clip(radius / pixel / SHADOW_CELLS_PER_RADIUS, 1, params.shadow_cell))
    return geo, Target(index=index, planes=plane_ids, centre=centre, radius=radius, fine_cell=fine_cell,
                       shadow_cell=shadow_cell, eps=1e-6 * geo.scale, surface_key=surface_keys(geo))


def scene_geometry(scene: SceneData) -> Geometry:
    """The scene's triangles in the probe frame (`build_geometry`)."""
    return build_geometry(scene.triangles, scene.tri_object, scene.object_names, scene.center, scene.rotation)


def object_index(scene: SceneData, object_name: str) -> int:
    """The index of `object_name` among the scene's objects; DimredError when there is none."""
    try:
        return scene.object_index(object_name)
    except KeyError:
        raise DimredError(f"no mesh object named '{object_name}' among the scene's proxy geometry") from None


def _plane_index(geo: Geometry, name: str) -> int:
    if name not in geo.object_names:
        raise DimredError(f"no mesh object named '{name}' for --plane")
    index = geo.object_names.index(name)
    if plane_of_object(geo, index) is None:
        raise DimredError(f"'{name}' is not planar: --plane takes flat surfaces only")
    return index
