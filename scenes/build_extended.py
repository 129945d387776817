"""Build the photo-textured rooms in bpy: `scenes.build`'s room, then a floor textured from a
real photograph, windows in the walls and chairs.

`scenes.build` and `scenes.render_job` are hashed into every scene's cache key, so what only
these rooms use is added here, after `scenes.build.build` has made the rest: the floor's
material is replaced by one that maps the baked photograph (`scenes.photo_texture`), a wall with
a window is rebuilt around a hole that an emitting quad fills (closed behind by a black housing,
as the ceiling lamps are, for the same reason), and a chair's mesh replaces the one `build`
gives any object of a kind it does not know. Its cache key includes this module
(`SceneSpec.extended`).

`python -m scenes.build_extended pair DIR` renders a pair as `scenes.render_job` does (see
there), with this module's `build`.
"""
from __future__ import annotations

import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

import bpy

from . import build as base
from . import render_job
from .photo_texture import baked_floor, baked_walls, wall_axis
from .spec import Room, SceneObject, SceneSpec, Window

if TYPE_CHECKING:
    import bmesh

# The housing only needs to close the hole; its depth is arbitrary.
_HOUSING_DEPTH = 0.05
# The sun sits this far inside the room, in front of the window's quad.
_SUN_INSET = 0.002


def build(spec: SceneSpec, include_removed: bool = True) -> None:
    """Create the scene of `spec` in `bpy.context.scene` (see `scenes.build.build`)."""
    base.build(spec, include_removed)
    scene = bpy.context.scene
    if spec.room.floor.photo is not None:
        floor = bpy.data.objects["Floor"]
        floor.data.materials.clear()
        floor.data.materials.append(_photo_floor_material(spec.room))
    if spec.room.wall_photo is not None:
        for wall, path in baked_walls(spec.room, spec.room.wall_photo).items():
            mesh = bpy.data.objects[f"Wall.{wall.capitalize()}"].data
            mesh.materials.clear()
            mesh.materials.append(_photo_wall_material(spec.room, wall, path))
    for wall in {w.wall for w in spec.windows}:
        _wall_with_windows(scene, spec.room, wall, [w for w in spec.windows if w.wall == wall])
    for obj in spec.objects:
        if obj.kind == "chair" and (include_removed or obj.name != spec.remove):
            _replace_mesh(bpy.data.objects[obj.name], lambda bm, o=obj: _chair(bm, o))


# --- floor ----------------------------------------------------------------------------------

def _photo_floor_material(room: Room) -> bpy.types.Material:
    """Diffuse BSDF whose albedo is the baked photograph, mapped by world x, y onto the floor's
    rectangle (packed into the .blend, which then stands alone)."""
    mat, nt = _textured("Floor", baked_floor(room, room.floor.photo))
    position = nt.nodes.new("ShaderNodeNewGeometry").outputs["Position"]
    _map_rectangle(nt, position, (room.lo[0], room.lo[1]), (room.hi[0], room.hi[1]))
    return mat


def _photo_wall_material(room: Room, wall: str, path: Path) -> bpy.types.Material:
    """As the floor's: the wall's texture mapped by (its axis, z) onto its rectangle."""
    mat, nt = _textured(f"Wall.{wall.capitalize()}", path)
    axis = wall_axis(wall)
    xyz = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(nt.nodes.new("ShaderNodeNewGeometry").outputs["Position"], xyz.inputs["Vector"])
    az = nt.nodes.new("ShaderNodeCombineXYZ")
    nt.links.new(xyz.outputs["XY"[axis]], az.inputs["X"])
    nt.links.new(xyz.outputs["Z"], az.inputs["Y"])
    _map_rectangle(nt, az.outputs["Vector"], (room.lo[axis], room.lo[2]), (room.hi[axis], room.hi[2]))
    return mat


def _textured(name: str, path: Path) -> tuple[bpy.types.Material, bpy.types.NodeTree]:
    """A Diffuse BSDF whose colour is an Image Texture node of `path` (packed, linear); the
    texture's vector is linked by `_map_rectangle`."""
    mat, nt = base._new_material(name)
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Roughness"].default_value = 0.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    image = bpy.data.images.load(str(path), check_existing=False)
    image.colorspace_settings.name = "Linear Rec.709"
    image.pack()
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = "Linear"
    tex.extension = "EXTEND"
    nt.links.new(tex.outputs["Color"], bsdf.inputs["Color"])
    return mat, nt


def _map_rectangle(nt: bpy.types.NodeTree, vector: bpy.types.NodeSocket, lo: tuple[float, float],
                   hi: tuple[float, float]) -> None:
    """Feed `vector`'s (x, y), mapped from the rectangle lo..hi onto 0..1, to the image texture."""
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    # (p - lo) / (hi - lo): the Mapping node scales after it translates, so translate by
    # -lo / (hi - lo) in scaled units. z is pinned to 0.5, away from any texel boundary.
    mapping.inputs["Scale"].default_value = (1 / (hi[0] - lo[0]), 1 / (hi[1] - lo[1]), 0.0)
    mapping.inputs["Location"].default_value = (-lo[0] / (hi[0] - lo[0]), -lo[1] / (hi[1] - lo[1]), 0.5)
    nt.links.new(vector, mapping.inputs["Vector"])
    tex = next(n for n in nt.nodes if n.bl_idname == "ShaderNodeTexImage")
    nt.links.new(mapping.outputs["Vector"], tex.inputs["Vector"])


# --- windows --------------------------------------------------------------------------------

def _wall_frame(room: Room, wall: str) -> tuple[Callable[[float, float], tuple[float, float, float]], bool, float]:
    """(point(a, z) on the wall's plane, a along it; whether quads wound a-first face into the
    room; the unit normal's sign along the wall's axis, x or y, pointing out of the room)."""
    (x0, y0, _), (x1, y1, _) = room.lo, room.hi
    frames = {
        "west": (lambda a, z: (x0, a, z), True, -1.0),
        "east": (lambda a, z: (x1, a, z), False, 1.0),
        "south": (lambda a, z: (a, y0, z), False, -1.0),
        "north": (lambda a, z: (a, y1, z), True, 1.0),
    }
    return frames[wall]


def _window_extent(w: Window) -> tuple[tuple[float, float], tuple[float, float]]:
    (a, z), (sa, sz) = w.center, w.size
    return (a - sa / 2, a + sa / 2), (z - sz / 2, z + sz / 2)


def _wall_with_windows(scene: bpy.types.Scene, room: Room, wall: str, windows: Sequence[Window]) -> None:
    """Rebuild `Wall.<Wall>` as a grid of quads less the windows' rectangles; each window gets
    an emitting quad in its hole (and a sun in front of it) and a black housing behind."""
    name = f"Wall.{wall.capitalize()}"
    material = bpy.data.objects[name].data.materials[0]
    bpy.data.objects.remove(bpy.data.objects[name])
    point, forward, out = _wall_frame(room, wall)
    axis = 1 if wall in ("west", "east") else 0  # the one along the wall; 1 - axis is its normal's
    holes = [_window_extent(w) for w in windows]
    az = sorted({room.lo[axis], room.hi[axis], *(a for h in holes for a in h[0])})
    zs = sorted({room.lo[2], room.hi[2], *(z for h in holes for z in h[1])})
    verts = [point(a, z) for a in az for z in zs]
    faces = []
    for i in range(len(az) - 1):
        for j in range(len(zs) - 1):
            ca, cz = (az[i] + az[i + 1]) / 2, (zs[j] + zs[j + 1]) / 2
            if any(ha0 < ca < ha1 and hz0 < cz < hz1 for (ha0, ha1), (hz0, hz1) in holes):
                continue
            a, b = i * len(zs) + j, (i + 1) * len(zs) + j
            faces.append((a, b, b + 1, a + 1) if forward else (a, a + 1, b + 1, b))
    base._mesh_object(scene, name, verts, faces, material)
    housing = base._diffuse("WindowHousing", (0.0, 0.0, 0.0))
    for w in windows:
        k = len([o for o in bpy.data.objects if o.name.startswith("Window.")]) + 1
        (a0, a1), (z0, z1) = _window_extent(w)
        _emitter(scene, f"Window.{k:03d}", point, (a0, a1), (z0, z1), 0.0, 1 - axis, w.color, w.strength)
        if w.sun_strength > 0:
            (a, z), s = w.center, w.sun_size / 2
            _emitter(scene, f"Sun.{k:03d}", point, (a - s, a + s), (z - s, z + s), -out * _SUN_INSET, 1 - axis,
                     w.sun_color, w.sun_strength)
        # Open towards the room: the back and four sides, `_HOUSING_DEPTH` out of the wall.
        depth = out * _HOUSING_DEPTH
        corners = [(a0, z0), (a1, z0), (a1, z1), (a0, z1)]
        verts = [_offset(point(a, z), 1 - axis, d) for d in (0.0, depth) for a, z in corners]
        faces = [(4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
        base._mesh_object(scene, f"WindowHousing.{k:03d}", verts, faces, housing)


def _offset(p: tuple[float, float, float], axis: int, d: float) -> tuple[float, float, float]:
    q = list(p)
    q[axis] += d
    return (q[0], q[1], q[2])


def _emitter(scene: bpy.types.Scene, name: str, point: Callable[[float, float], tuple[float, float, float]],
             ar: tuple[float, float], zr: tuple[float, float], inset: float, normal_axis: int,
             color: Sequence[float], strength: float) -> None:
    """A two-sided emitting quad on the wall's plane, moved `inset` along its normal's axis."""
    verts = [_offset(point(a, z), normal_axis, inset)
             for a, z in ((ar[0], zr[0]), (ar[1], zr[0]), (ar[1], zr[1]), (ar[0], zr[1]))]
    base._quad_object(scene, name, verts, base._emission(name, color, strength))


# --- chairs ---------------------------------------------------------------------------------

def _replace_mesh(obj: bpy.types.Object, make: Callable[[bmesh.types.BMesh], None]) -> None:
    import bmesh  # importable only once bpy is (run as a module, this one imports bpy first)

    bm = bmesh.new()
    make(bm)
    mesh = bpy.data.meshes.new(obj.name)
    bm.to_mesh(mesh)
    bm.free()
    mesh.materials.append(obj.data.materials[0])
    obj.data = mesh


def _chair(bm: bmesh.types.BMesh, spec: SceneObject) -> None:
    """Seat, four corner legs and a back on the -y side: two posts continuing the rear legs up
    to the top and a rest between them over the back's upper half."""
    sx, sy, sz = spec.size
    t, w, seat = spec.seat_thickness, spec.leg_width, spec.seat_height
    base._box(bm, (0.0, 0.0, seat - t), (sx, sy, t))
    lx, ly = sx / 2 - w / 2, sy / 2 - w / 2
    for x in (-lx, lx):
        base._box(bm, (x, ly, 0.0), (w, w, seat - t))
        base._box(bm, (x, -ly, 0.0), (w, w, sz))
    rest = (sz - seat) / 2
    base._box(bm, (0.0, -ly, sz - rest), (sx - 2 * w, w, rest))


if __name__ == "__main__":
    if sys.argv[1:2] == ["pair"] and len(sys.argv) == 3:
        # render_job's pair job, building with this module (render_job itself must stay as it
        # is: it is hashed into every scene's key).
        render_job.build = build
        render_job.run_pair(Path(sys.argv[2]))
    else:
        sys.exit("usage: python -m scenes.build_extended pair DIR")
