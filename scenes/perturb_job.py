"""The subprocess behind `scenes.perturb.perturbed_blend`, so that Blender's state stays out of
the caller (its own module, so that the render cache keys, which hash `render_job.py`, stay).

`python -m scenes.perturb_job BLEND OBJECT ERROR_JSON OUT_BLEND RESULT_JSON` opens BLEND, for a
`box` error replaces OBJECT's mesh by its bounding box in its own frame, moves OBJECT by the
error's matrix about its bottom centre (world bounding box of its exact mesh), raises
the object "Floor" by the error's `floor`, saves the copy OUT_BLEND (relative paths remapped, so
it still shows the pair's panorama) and writes RESULT_JSON: the exact proxy's `bottom_centre`
and `exact_matrix`.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import bpy
import numpy as np
from mathutils import Matrix

from .perturb import ProxyError, error_matrix


def _world_vertices(obj: bpy.types.Object) -> np.ndarray:
    mesh = obj.data
    co = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    m = np.array(obj.matrix_world)
    return co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]


def _moved(obj: bpy.types.Object, e: np.ndarray) -> None:
    obj.matrix_world = Matrix((e @ np.array(obj.matrix_world)).tolist())


def _bounding_box_mesh(obj: bpy.types.Object) -> bpy.types.Mesh:
    """A new mesh: the six faces, turned outwards, of `obj`'s bounding box in its own frame."""
    box = np.array([tuple(corner) for corner in obj.bound_box])
    lo, hi = box.min(axis=0), box.max(axis=0)
    corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh = bpy.data.meshes.new(f"{obj.name}.box")
    mesh.from_pydata([tuple(map(float, c)) for c in corners], [], faces)
    mesh.update()
    return mesh


def run(blend: Path, object_name: str, error: ProxyError, out_blend: Path, result: Path) -> None:
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    obj = bpy.data.objects.get(object_name)
    if obj is None or obj.type != "MESH":
        sys.exit(f"no mesh object {object_name!r} in {blend}")
    floor = bpy.data.objects.get("Floor")
    if error.floor and floor is None:
        sys.exit(f"a floor error needs an object 'Floor' in {blend}")
    points = _world_vertices(obj)
    lo, hi = points.min(axis=0), points.max(axis=0)
    bottom = [float(lo[0] + hi[0]) / 2, float(lo[1] + hi[1]) / 2, float(lo[2])]
    exact = np.array(obj.matrix_world)
    if error.box:
        obj.data = _bounding_box_mesh(obj)
    _moved(obj, error_matrix(error, bottom))
    if error.floor:
        lift = np.eye(4)
        lift[2, 3] = error.floor
        _moved(floor, lift)
    bpy.ops.wm.save_as_mainfile(filepath=str(out_blend), copy=True, relative_remap=True)
    result.write_text(json.dumps({"bottom_centre": bottom, "exact_matrix": exact.tolist()}))


if __name__ == "__main__":
    if len(sys.argv) != 6:
        sys.exit("usage: python -m scenes.perturb_job BLEND OBJECT ERROR_JSON OUT_BLEND RESULT_JSON")
    fields = json.loads(sys.argv[3])
    run(Path(sys.argv[1]), sys.argv[2], ProxyError(**dict(fields, shift=tuple(fields["shift"]))),
        Path(sys.argv[4]), Path(sys.argv[5]))
