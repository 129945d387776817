"""Build a `SceneSpec` in the current bpy session: the closed room, lamps, objects, camera.

Every surface is a pure Lambertian Diffuse BSDF (the engine's model). Each lamp is a
two-sided emitting quad filling a hole in the ceiling, closed above by a black housing:
emission restricted to one side through the shader makes Cycles' light tree mis-estimate the
lamp, and direct light came out much noisier that way (seen on Blender 5.0). The panoramic
camera at the probe centre renders the panorama that the World's Environment Texture, through
the spec's Mapping rotation, maps back onto the scene.
Expects a fresh session (`bpy.ops.wm.read_factory_settings(use_empty=True)`).
"""
from __future__ import annotations

import math
from collections.abc import Sequence

import bmesh
import bpy
from mathutils import Matrix

from .spec import Floor, Lamp, Render, Room, SceneObject, SceneSpec

# Lamp housings only need to close the holes; their depth is arbitrary.
_HOUSING_DEPTH = 0.05
_SEGMENTS = 48


def build(spec: SceneSpec, include_removed: bool = True) -> None:
    """Create the scene of `spec` in `bpy.context.scene`, with a black world."""
    scene = bpy.context.scene
    configure_cycles(scene, spec.render)
    _room(scene, spec.room, spec.lamps)
    for obj in spec.objects:
        if include_removed or obj.name != spec.remove:
            _object(scene, obj, spec.room)
    probe = bpy.data.objects.new("ProbeCenter", None)
    probe.empty_display_type = "SPHERE"
    probe.empty_display_size = 0.1
    probe.location = spec.probe
    scene.collection.objects.link(probe)
    _camera(scene, spec)
    set_black_world(scene)


def configure_cycles(scene: bpy.types.Scene, render: Render) -> None:
    """Unbiased, unclamped, undenoised CPU Cycles with a fixed seed and point-sampled pixels."""
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = render.samples
    cy.seed = render.seed
    cy.use_animated_seed = False
    # Adaptive sampling and path guiding adapt to the image, so the with/without-object renders
    # would stop sharing their random numbers; both are off to keep their noise correlated.
    cy.use_adaptive_sampling = False
    cy.use_guiding = False
    cy.use_denoising = False
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    # A 0.01 px Blackman-Harris filter samples each pixel's centre direction (BOX is always 1 px).
    cy.pixel_filter_type = "BLACKMAN_HARRIS"
    cy.filter_width = 0.01
    cy.max_bounces = render.max_bounces
    cy.diffuse_bounces = render.max_bounces
    cy.glossy_bounces = 0
    cy.transmission_bounces = 0
    cy.volume_bounces = 0
    cy.use_light_tree = True
    scene.render.film_transparent = False
    scene.render.resolution_x = render.width
    scene.render.resolution_y = render.height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = "Standard"
    scene.view_settings.look = "None"
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    img = scene.render.image_settings
    img.file_format = "OPEN_EXR"
    img.color_mode = "RGB"
    img.color_depth = "32"
    img.exr_codec = "ZIP"
    scene.render.use_file_extension = False


def set_black_world(scene: bpy.types.Scene) -> None:
    """A world that emits nothing (the ground-truth room is closed anyway)."""
    world = bpy.data.worlds.new("Black")
    nt = world.node_tree
    nt.nodes.clear()
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    bg.inputs["Strength"].default_value = 0.0
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    scene.world = world


def set_environment_world(scene: bpy.types.Scene, image_path: str, rotation_z_deg: float,
                          interpolation: str = "Linear") -> None:
    """The user's world: Environment Texture(image) -> Background, through a Z-rotating
    Mapping node (Point) fed by the Generated coordinates when `rotation_z_deg` is non-zero."""
    world = bpy.data.worlds.new("Environment")
    nt = world.node_tree
    nt.nodes.clear()
    image = bpy.data.images.load(image_path, check_existing=False)
    image.colorspace_settings.name = "Linear Rec.709"
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = image
    env.interpolation = interpolation
    env.projection = "EQUIRECTANGULAR"
    if rotation_z_deg:
        coords = nt.nodes.new("ShaderNodeTexCoord")
        mapping = nt.nodes.new("ShaderNodeMapping")
        mapping.vector_type = "POINT"
        mapping.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(rotation_z_deg))
        nt.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
        nt.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    bg = nt.nodes.new("ShaderNodeBackground")
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    scene.world = world


def use_mask_materials(scene: bpy.types.Scene, name: str) -> None:
    """Replace every mesh's materials: object `name` emits 1, everything else is black."""
    white = _emission("MaskWhite", (1.0, 1.0, 1.0), 1.0)
    black = _emission("MaskBlack", (0.0, 0.0, 0.0), 0.0)
    for obj in scene.objects:
        if obj.type == "MESH":
            obj.data.materials.clear()
            obj.data.materials.append(white if obj.name == name else black)


# --- room -----------------------------------------------------------------------------------

def _room(scene: bpy.types.Scene, room: Room, lamps: Sequence[Lamp]) -> None:
    (x0, y0, z0), (x1, y1, z1) = room.lo, room.hi
    walls = _diffuse("Walls", room.wall_albedo)
    # Quads wound so that their normals point into the room.
    _quad_object(scene, "Floor", [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)],
                 _floor_material(room.floor))
    _quad_object(scene, "Wall.West",
                 [(x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1)], walls)
    _quad_object(scene, "Wall.East",
                 [(x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0)], walls)
    _quad_object(scene, "Wall.South",
                 [(x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0)], walls)
    _quad_object(scene, "Wall.North",
                 [(x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)], walls)
    _ceiling(scene, room, lamps)
    housing = _diffuse("LampHousing", (0.0, 0.0, 0.0))
    for i, lamp in enumerate(lamps, start=1):
        (lx0, lx1), (ly0, ly1) = _lamp_extent(lamp)
        mat = _emission(f"Lamp.{i:03d}", lamp.color, lamp.strength)
        _quad_object(scene, f"Lamp.{i:03d}",
                     [(lx0, ly0, z1), (lx0, ly1, z1), (lx1, ly1, z1), (lx1, ly0, z1)], mat)
        _housing(scene, f"LampHousing.{i:03d}", (lx0, lx1), (ly0, ly1), z1, housing)


def _lamp_extent(lamp: Lamp) -> tuple[tuple[float, float], tuple[float, float]]:
    (cx, cy), (sx, sy) = lamp.center, lamp.size
    return (cx - sx / 2, cx + sx / 2), (cy - sy / 2, cy + sy / 2)


def _ceiling(scene: bpy.types.Scene, room: Room, lamps: Sequence[Lamp]) -> None:
    """The ceiling plane minus the lamp rectangles, as a grid of quads on all their edges."""
    (x0, y0, _), (x1, y1, z1) = room.lo, room.hi
    holes = [_lamp_extent(lamp) for lamp in lamps]
    xs = sorted({x0, x1, *(x for h in holes for x in h[0])})
    ys = sorted({y0, y1, *(y for h in holes for y in h[1])})
    verts = [(x, y, z1) for x in xs for y in ys]
    faces = []
    for i in range(len(xs) - 1):
        for j in range(len(ys) - 1):
            cx, cy = (xs[i] + xs[i + 1]) / 2, (ys[j] + ys[j + 1]) / 2
            if any(hx0 < cx < hx1 and hy0 < cy < hy1 for (hx0, hx1), (hy0, hy1) in holes):
                continue
            a, b = i * len(ys) + j, (i + 1) * len(ys) + j
            faces.append((a, a + 1, b + 1, b))  # clockwise from above: normal points down
    _mesh_object(scene, "Ceiling", verts, faces, _diffuse("Ceiling", room.ceiling_albedo))


def _housing(scene: bpy.types.Scene, name: str, xr: tuple[float, float],
             yr: tuple[float, float], z: float, mat: bpy.types.Material) -> None:
    """Open-bottomed black box above a lamp hole."""
    top = z + _HOUSING_DEPTH
    verts = [(x, y, h) for h in (z, top) for x, y in
             ((xr[0], yr[0]), (xr[1], yr[0]), (xr[1], yr[1]), (xr[0], yr[1]))]
    faces = [(4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    _mesh_object(scene, name, verts, faces, mat)


# --- objects --------------------------------------------------------------------------------

def _object(scene: bpy.types.Scene, spec: SceneObject, room: Room) -> None:
    """A closed mesh with its origin at the bottom centre, rotated about Z by the object."""
    bm = bmesh.new()
    sx, sy, sz = spec.size
    if spec.kind == "box":
        _box(bm, (0.0, 0.0, 0.0), spec.size)
    elif spec.kind == "cylinder":
        _cylinder(bm, (0.0, 0.0, 0.0), spec.size)
    elif spec.kind == "sphere":
        bmesh.ops.create_uvsphere(bm, u_segments=_SEGMENTS, v_segments=_SEGMENTS // 2, radius=0.5,
                                  matrix=Matrix.Translation((0, 0, sz / 2))
                                  @ Matrix.Diagonal((sx, sy, sz, 1.0)))
    else:
        _stool(bm, spec)
    mesh = bpy.data.meshes.new(spec.name)
    bm.to_mesh(mesh)
    bm.free()
    mesh.materials.append(_diffuse(spec.name, spec.albedo))
    obj = bpy.data.objects.new(spec.name, mesh)
    obj.location = spec.location
    obj.rotation_euler = (0.0, 0.0, math.radians(spec.rotation_z))
    scene.collection.objects.link(obj)


def _box(bm: bmesh.types.BMesh, bottom: Sequence[float], size: Sequence[float]) -> None:
    m = Matrix.Translation((bottom[0], bottom[1], bottom[2] + size[2] / 2))
    bmesh.ops.create_cube(bm, size=1.0, matrix=m @ Matrix.Diagonal((*size, 1.0)))


def _cylinder(bm: bmesh.types.BMesh, bottom: Sequence[float], size: Sequence[float]) -> None:
    m = Matrix.Translation((bottom[0], bottom[1], bottom[2] + size[2] / 2))
    bmesh.ops.create_cone(bm, cap_ends=True, segments=_SEGMENTS, radius1=0.5, radius2=0.5,
                          depth=1.0, matrix=m @ Matrix.Diagonal((*size, 1.0)))


def _stool(bm: bmesh.types.BMesh, spec: SceneObject) -> None:
    sx, sy, sz = spec.size
    t, w = spec.seat_thickness, spec.leg_width
    seat = _cylinder if spec.seat == "round" else _box
    seat(bm, (0.0, 0.0, sz - t), (sx, sy, t))
    for k in range(spec.legs):
        a = math.radians(45.0 + 360.0 * k / spec.legs)
        if spec.seat == "square" and spec.legs == 4:
            # Square seat: legs in the corners, inset by 1.5 leg widths.
            x, y = (math.copysign(sx / 2 - 1.5 * w, math.cos(a)),
                    math.copysign(sy / 2 - 1.5 * w, math.sin(a)))
        else:
            x, y = (sx / 2 - 1.5 * w) * math.cos(a), (sy / 2 - 1.5 * w) * math.sin(a)
        _box(bm, (x, y, 0.0), (w, w, sz - t))


# --- helpers --------------------------------------------------------------------------------

def _camera(scene: bpy.types.Scene, spec: SceneSpec) -> None:
    cam = bpy.data.cameras.new("ProbeCamera")
    cam.type = "PANO"
    cam.panorama_type = "EQUIRECTANGULAR"
    cam.longitude_min, cam.longitude_max = -math.pi, math.pi
    cam.latitude_min, cam.latitude_max = -math.pi / 2, math.pi / 2
    cam.clip_start = 0.001
    cam.clip_end = 1000.0
    obj = bpy.data.objects.new("ProbeCamera", cam)
    obj.location = spec.probe
    # (90, 0, -90) degrees renders the Environment Texture's own mapping (image direction t ->
    # world t). The Mapping node samples the texture at t = Rz(a) d, so pixel t must show
    # world direction Rz(-a) t: rotate the camera by -a about world Z.
    obj.rotation_euler = (math.pi / 2, 0.0, -math.pi / 2 - math.radians(spec.world_rotation_z))
    scene.collection.objects.link(obj)
    scene.camera = obj


def _quad_object(scene: bpy.types.Scene, name: str, verts: list[tuple[float, float, float]],
                 mat: bpy.types.Material) -> None:
    _mesh_object(scene, name, verts, [(0, 1, 2, 3)], mat)


def _mesh_object(scene: bpy.types.Scene, name: str, verts: list[tuple[float, float, float]],
                 faces: list[tuple[int, ...]], mat: bpy.types.Material) -> None:
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.validate()
    mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)


def _new_material(name: str) -> tuple[bpy.types.Material, bpy.types.NodeTree]:
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    nt.nodes.clear()
    return mat, nt


def _rgba(rgb: Sequence[float]) -> tuple[float, float, float, float]:
    return (rgb[0], rgb[1], rgb[2], 1.0)


def _diffuse(name: str, albedo: Sequence[float]) -> bpy.types.Material:
    mat, nt = _new_material(name)
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = _rgba(albedo)
    bsdf.inputs["Roughness"].default_value = 0.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    mat.diffuse_color = _rgba(albedo)
    return mat


def _emission(name: str, color: Sequence[float], strength: float) -> bpy.types.Material:
    mat, nt = _new_material(name)
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = _rgba(color)
    em.inputs["Strength"].default_value = strength
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
    return mat


def _input(node: bpy.types.Node, name: str) -> bpy.types.NodeSocket:
    # Nodes such as Mix carry one socket per data type under the same name; take the live one.
    return next(s for s in node.inputs if s.name == name and s.enabled)


def _floor_material(floor: Floor) -> bpy.types.Material:
    """Diffuse BSDF whose albedo is a procedural texture of world position, in metres."""
    mat, nt = _new_material("Floor")
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Roughness"].default_value = 0.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    if floor.pattern == "plain":
        bsdf.inputs["Color"].default_value = _rgba(floor.color1)
        return mat
    position = nt.nodes.new("ShaderNodeNewGeometry").outputs["Position"]

    def scaled(sx: float, sy: float) -> bpy.types.NodeSocket:
        # z is pinned to 0.5: hit points on the floor plane jitter around z = 0, and the
        # checker's floor(z) would flip the colour at random there.
        m = nt.nodes.new("ShaderNodeMapping")
        m.vector_type = "POINT"
        m.inputs["Scale"].default_value = (sx, sy, 0.0)
        m.inputs["Location"].default_value = (0.0, 0.0, 0.5)
        nt.links.new(position, m.inputs["Vector"])
        return m.outputs["Vector"]

    if floor.pattern == "checker":
        tex = nt.nodes.new("ShaderNodeTexChecker")
        tex.inputs["Color1"].default_value = _rgba(floor.color1)
        tex.inputs["Color2"].default_value = _rgba(floor.color2)
        tex.inputs["Scale"].default_value = 1.0
        nt.links.new(scaled(1 / floor.scale, 1 / floor.scale), tex.inputs["Vector"])
        color = tex.outputs["Color"]
    elif floor.pattern == "planks":
        # Planks run along x: `scale` wide, six times as long, half-offset every other row,
        # each a random shade between the two colours, with a fine grain along x.
        tex = nt.nodes.new("ShaderNodeTexBrick")
        tex.offset, tex.offset_frequency = 0.5, 2
        tex.inputs["Color1"].default_value = _rgba(floor.color1)
        tex.inputs["Color2"].default_value = _rgba(floor.color2)
        tex.inputs["Mortar"].default_value = _rgba([0.35 * c for c in floor.color1])
        tex.inputs["Scale"].default_value = 1.0
        tex.inputs["Mortar Size"].default_value = 0.004
        tex.inputs["Bias"].default_value = 0.0
        tex.inputs["Brick Width"].default_value = 6.0 * floor.scale
        tex.inputs["Row Height"].default_value = floor.scale
        nt.links.new(scaled(1.0, 1.0), tex.inputs["Vector"])
        grain = nt.nodes.new("ShaderNodeTexNoise")
        grain.inputs["Scale"].default_value = 1.0
        grain.inputs["Detail"].default_value = 2.0
        nt.links.new(scaled(2.0, 40.0), grain.inputs["Vector"])
        shade = nt.nodes.new("ShaderNodeMapRange")
        for k, v in (("From Min", 0.3), ("From Max", 0.7), ("To Min", 0.85), ("To Max", 1.1)):
            _input(shade, k).default_value = v
        nt.links.new(grain.outputs["Factor"], _input(shade, "Value"))
        mix = nt.nodes.new("ShaderNodeMix")
        mix.data_type, mix.blend_type = "RGBA", "MULTIPLY"
        _input(mix, "Factor").default_value = 1.0
        nt.links.new(tex.outputs["Color"], _input(mix, "A"))
        nt.links.new(shade.outputs["Result"], _input(mix, "B"))
        color = next(s for s in mix.outputs if s.enabled)
    else:  # noise
        tex = nt.nodes.new("ShaderNodeTexNoise")
        tex.inputs["Scale"].default_value = 1.0
        tex.inputs["Detail"].default_value = 3.0
        nt.links.new(scaled(1 / floor.scale, 1 / floor.scale), tex.inputs["Vector"])
        fac = nt.nodes.new("ShaderNodeMapRange")
        for k, v in (("From Min", 0.35), ("From Max", 0.65), ("To Min", 0.0), ("To Max", 1.0)):
            _input(fac, k).default_value = v
        nt.links.new(tex.outputs["Factor"], _input(fac, "Value"))
        mix = nt.nodes.new("ShaderNodeMix")
        mix.data_type = "RGBA"
        _input(mix, "A").default_value = _rgba(floor.color1)
        _input(mix, "B").default_value = _rgba(floor.color2)
        nt.links.new(fac.outputs["Result"], _input(mix, "Factor"))
        color = next(s for s in mix.outputs if s.enabled)
    nt.links.new(color, bsdf.inputs["Color"])
    return mat
