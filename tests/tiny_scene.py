"""A tiny procedural room for end-to-end tests, on any bpy from 4.2 on.

A 4 x 4 x 3 m room (floor, walls and ceiling), a square lamp in the ceiling, a red 0.6 m box on
the floor, and a 64 x 32 lat-long HDRI seen from the probe centre that matches it roughly (the
lamp, the box, and the box's shadow on a tiled floor). Meant to be fast, not exact.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

CENTER = (0.0, 0.0, 1.2)
ROOM = ((-2.0, -2.0, 0.0), (2.0, 2.0, 3.0))
BOX = ((0.7, -0.3, 0.0), (1.3, 0.3, 0.6))
LAMP_HALF = 0.3
LAMP_Z = ROOM[1][2] - 0.01


def write_exr(path: str | Path, rgb: np.ndarray) -> None:
    """RGB float32 EXR, row 0 at the top (written with OpenEXR, independent of the engine)."""
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {"RGB": np.ascontiguousarray(rgb, dtype=np.float32)}) as exr:
        exr.write(str(path))


def read_exr(path: str | Path) -> np.ndarray:
    """(H, W, 3) float32 pixels of an RGB EXR, row 0 at the top."""
    import OpenEXR

    with OpenEXR.File(str(path)) as exr:
        channels = exr.channels()
        if "RGB" in channels:
            return np.asarray(channels["RGB"].pixels, dtype=np.float32)
        return np.stack([np.asarray(channels[c].pixels, dtype=np.float32) for c in "RGB"], axis=-1)


def _ray_box(origin: np.ndarray, d: np.ndarray, lo: tuple, hi: tuple) -> np.ndarray:
    """Entry distance of rays into an axis-aligned box, inf where they miss (slab test)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (np.asarray(lo) - origin) / d
        t2 = (np.asarray(hi) - origin) / d
    near = np.nanmax(np.minimum(t1, t2), axis=-1)
    far = np.nanmin(np.maximum(t1, t2), axis=-1)
    return np.where((far >= np.maximum(near, 0.0)) & (near > 0.0), near, np.inf)


def synthetic_hdri(width: int = 64, height: int = 32) -> np.ndarray:
    """(H, W, 3) float32 radiance of the room seen from CENTER (Blender's equirectangular map)."""
    u = (np.arange(width) + 0.5) / width
    v = 1.0 - (np.arange(height) + 0.5) / height
    phi = (0.5 - u[None, :]) * 2.0 * np.pi
    theta = (1.0 - v[:, None]) * np.pi
    d = np.stack(np.broadcast_arrays(np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)), -1)
    c = np.asarray(CENTER)

    # Leaving a convex room from inside: the nearest positive wall distance per axis.
    with np.errstate(divide="ignore"):
        t_wall = np.where(d > 0, (np.asarray(ROOM[1]) - c) / d, (np.asarray(ROOM[0]) - c) / d)
    t_wall = np.where(np.isfinite(t_wall) & (t_wall > 0), t_wall, np.inf)
    axis = np.argmin(t_wall, axis=-1)
    t = np.min(t_wall, axis=-1)
    p = c + d * t[..., None]

    rgb = np.full(d.shape, 0.6, dtype=np.float32)  # walls
    floor = (axis == 2) & (d[..., 2] < 0)
    ceiling = (axis == 2) & (d[..., 2] > 0)
    tiles = (np.floor(p[..., 0] / 0.25) + np.floor(p[..., 1] / 0.25)) % 2
    rgb[floor] = (0.35 + 0.2 * tiles[floor])[:, None]
    rgb[ceiling] = 0.5
    lamp = ceiling & (np.abs(p[..., 0]) <= LAMP_HALF) & (np.abs(p[..., 1]) <= LAMP_HALF)
    rgb[lamp] = 25.0

    # The box's shadow from the lamp's centre on the floor.
    to_lamp = np.asarray((0.0, 0.0, LAMP_Z)) - p
    dist = np.linalg.norm(to_lamp, axis=-1)
    shadowed = floor & (_ray_box(p, to_lamp / dist[..., None], *BOX) < dist)
    rgb[shadowed] *= 0.3

    box = _ray_box(c, d, *BOX) < t
    rgb[box] = (0.5, 0.06, 0.05)
    return rgb


def _mesh_object(bpy, name: str, vertices: list, faces: list):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def box_triangles(lo, hi) -> np.ndarray:
    """(12, 3, 3) triangles of the axis-aligned box from corner `lo` to corner `hi`."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c = np.array([[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])])
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return c[np.array(faces)]


def _box_faces(lo: tuple, hi: tuple) -> tuple[list, list]:
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    vertices = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
                (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return vertices, faces


def build_scene(hdri_path: str | Path) -> None:
    """Fill the current (empty) Blender scene with the room, lit by the HDRI at hdri_path."""
    import bpy

    (x0, y0, _), (x1, y1, z1) = ROOM
    _mesh_object(bpy, "Floor", [(x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0)], [(0, 1, 2, 3)])
    room_vertices, room_faces = _box_faces(*ROOM)
    # The room without its floor, faces turned inwards.
    _mesh_object(bpy, "Room", room_vertices, [tuple(reversed(f)) for f in room_faces[1:]])
    h = LAMP_HALF
    _mesh_object(bpy, "Lamp", [(-h, -h, LAMP_Z), (-h, h, LAMP_Z), (h, h, LAMP_Z), (h, -h, LAMP_Z)], [(0, 1, 2, 3)])
    _mesh_object(bpy, "Box", *_box_faces(*BOX))
    probe = bpy.data.objects.new("ProbeCenter", None)
    probe.location = CENTER
    bpy.context.scene.collection.objects.link(probe)

    world = bpy.data.worlds.new("Room Probe")
    if world.node_tree is None:
        world.use_nodes = True  # Blender 4.x creates worlds without a node tree
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = next(n for n in nodes if n.type == 'BACKGROUND')
    environment = nodes.new("ShaderNodeTexEnvironment")
    environment.image = bpy.data.images.load(str(hdri_path))
    links.new(environment.outputs["Color"], background.inputs["Color"])
    bpy.context.scene.world = world


def render_world(width: int, height: int, origin, path: str | Path) -> np.ndarray:
    """Render the current scene's world with Cycles from `origin` through an equirectangular
    panoramic camera into the EXR `path`; return (height, width, 3) float32, top row first.

    One sample with a 0.01 px Blackman-Harris filter point-samples each pixel's centre
    direction; the camera rotation (90, 0, -90) degrees makes the render's pixel directions
    those of `addon.geometry.latlong.pixel_directions`. Keep sizes tiny: the machine is shared.
    """
    import math

    import bpy

    scene = bpy.context.scene
    camera_data = bpy.data.cameras.new("ProbeCamera")
    camera_data.type = 'PANO'
    camera_data.panorama_type = 'EQUIRECTANGULAR'
    camera_data.longitude_min, camera_data.longitude_max = -math.pi, math.pi
    camera_data.latitude_min, camera_data.latitude_max = -math.pi / 2, math.pi / 2
    camera = bpy.data.objects.new("ProbeCamera", camera_data)
    scene.collection.objects.link(camera)
    camera.location = origin
    camera.rotation_euler = (math.pi / 2, 0.0, -math.pi / 2)
    scene.camera = camera
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = 1
    scene.cycles.use_adaptive_sampling = False
    scene.cycles.use_denoising = False
    scene.cycles.pixel_filter_type = 'BLACKMAN_HARRIS'
    scene.cycles.filter_width = 0.01
    scene.render.threads_mode = 'FIXED'
    scene.render.threads = 2
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.use_compositing = False
    scene.render.use_sequencer = False
    scene.view_settings.view_transform = 'Standard'
    settings = scene.render.image_settings
    settings.file_format = 'OPEN_EXR'
    settings.color_depth = '32'
    settings.color_mode = 'RGB'
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    bpy.data.objects.remove(camera)
    bpy.data.cameras.remove(camera_data)
    return read_exr(path)


def scene_data(folder: str | Path, width: int, height: int):
    """The room as the engine sees it (`addon.scene.SceneData`), read through the bridge from a
    scene built in a fresh Blender session with a `width` x `height` panorama in `folder`; the
    session is emptied again afterwards."""
    import bpy

    from addon.blender import reader as bridge

    bpy.ops.wm.read_factory_settings(use_empty=True)
    hdri = Path(folder) / "room.exr"
    write_exr(hdri, synthetic_hdri(width, height))
    build_scene(hdri)
    scene = bridge.read_scene(bpy.context.scene)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return scene
