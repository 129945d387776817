"""The tiny procedural room (`tests.engine.tiny_room`) built in Blender, for end-to-end tests on
any bpy from 4.2 on: the same constants, meshes and synthetic HDRI, turned into Blender objects
and a world, plus a Cycles render of the world as a lat-long panorama.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from tests.engine.tiny_room import (  # noqa: F401  (re-exported: the Blender tests use the room through this module)
    BOX,
    CENTER,
    CRATE,
    LAMP_HALF,
    LAMP_Z,
    ROOM,
    box_faces,
    box_triangles,
    meshes,
    read_exr,
    synthetic_hdri,
    write_exr,
)


def mesh_object(bpy, name: str, vertices: list, faces: list):
    """A mesh object `name` linked into the current scene, at the origin."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(vertices, [], faces)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def add_crate(bpy, hdri_path: str | Path):
    """The CRATE as a mesh object, and the world's panorama (the image at `hdri_path`) rewritten
    to show it: a proxy the photograph does not show is refused."""
    crate = mesh_object(bpy, "Crate", *box_faces(*CRATE))
    wanted = Path(hdri_path).resolve()
    image = next(i for i in bpy.data.images if Path(bpy.path.abspath(i.filepath)).resolve() == wanted)
    write_exr(hdri_path, synthetic_hdri(image.size[0], image.size[1], crate=True))
    image.reload()
    return crate


def environment_world(bpy, name: str, image):
    """A new world `name` whose Background shows `image` through an Environment Texture;
    returns (world, the Environment Texture node)."""
    world = bpy.data.worlds.new(name)
    if world.node_tree is None:
        world.use_nodes = True  # Blender 4.x creates worlds without a node tree
    nodes, links = world.node_tree.nodes, world.node_tree.links
    background = next(n for n in nodes if n.type == 'BACKGROUND')
    environment = nodes.new("ShaderNodeTexEnvironment")
    environment.image = image
    links.new(environment.outputs["Color"], background.inputs["Color"])
    return world, environment


def build_scene(hdri_path: str | Path) -> None:
    """Fill the current (empty) Blender scene with the room, lit by the HDRI at hdri_path."""
    import bpy

    for name, (vertices, faces) in meshes().items():
        mesh_object(bpy, name, vertices, faces)
    probe = bpy.data.objects.new("ProbeCenter", None)
    probe.location = CENTER
    bpy.context.scene.collection.objects.link(probe)

    world, _ = environment_world(bpy, "Room Probe", bpy.data.images.load(str(hdri_path)))
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
    """The room as the engine sees it (`addon.scene.SceneData`), read through the reader from a
    scene built in a fresh Blender session with a `width` x `height` panorama in `folder`; the
    session is emptied again afterwards."""
    import bpy

    from addon.blender import reader

    bpy.ops.wm.read_factory_settings(use_empty=True)
    hdri = Path(folder) / "room.exr"
    write_exr(hdri, synthetic_hdri(width, height))
    build_scene(hdri)
    scene = reader.read_scene(bpy.context.scene)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    return scene
