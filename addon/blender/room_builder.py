"""Match Room in Blender: the fitted room as the mesh objects Floor, Walls and Ceiling, the probe
centre where the camera was, and the clicks kept on the scene.

Objects of those names are reused (their materials kept, their meshes replaced), so a re-fit
after a moved click updates the room in place. Nothing is changed when the clicks show no room:
every check runs before the first object is touched.
"""
from __future__ import annotations

import bpy
import numpy as np

from ..errors import DimredError
from ..roommatch import clicks as click_file
from ..roommatch.clicks import RoomClicks
from ..roommatch.fit import DEFAULT_CEILING_HEIGHT, RoomFit, fit_room
from ..roommatch.meshes import NAMES, MeshData, room_meshes
from ..roommatch.projection import project
from . import reader

_BOX_FACES = ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))
#: The scene's custom property holding the last matched room's click file (JSON).
CLICKS_PROPERTY = "dimred_room_clicks"


def panorama_rotation(scene: bpy.types.Scene) -> np.ndarray:
    """The world's Mapping rotation, the identity where the scene has no panorama yet."""
    try:
        return reader.texture_rotation(reader.environment_texture(scene))
    except DimredError:
        return np.eye(3)


def panorama_pixel(scene: bpy.types.Scene, direction: np.ndarray) -> tuple[float, float, int, int]:
    """The pixel (x, y) of the world's panorama that the world `direction` (3,) shows (through the
    world's Mapping rotation), and the panorama's width and height: where a click in a 3D viewport
    showing the world lands in the panorama."""
    width, height = reader.panorama_size(scene)
    x, y = project(np.asarray(direction, dtype=np.float64), width, height, panorama_rotation(scene))
    return float(x), float(y), width, height


def probe_camera(scene: bpy.types.Scene, name: str = "Probe Camera") -> bpy.types.Object:
    """The camera `name` (made where missing: a wide lens looking level) moved to the probe centre
    and made the scene's camera, so that looking through it shows the panorama as seen from there."""
    obj = scene.objects.get(name)
    if obj is None or obj.type != 'CAMERA':
        data = bpy.data.cameras.new(name)
        data.lens, data.clip_start = 12.0, 0.01  # 113 degrees across on a 36 mm sensor
        obj = bpy.data.objects.new(name, data)
        obj.rotation_euler = (np.pi / 2, 0.0, 0.0)
        scene.collection.objects.link(obj)
    obj.location = tuple(reader.probe_center(scene))
    scene.camera = obj
    return obj


def match_room(scene: bpy.types.Scene, clicks: RoomClicks, *,
               ceiling_height: float = DEFAULT_CEILING_HEIGHT) -> RoomFit:
    """Fit the room the clicks show and build it in `scene`; DimredError and nothing changed when
    the clicks show none or an object in the way is not a mesh."""
    rotation = panorama_rotation(scene)
    # The room is built round the probe centre where the scene has one: only its height changes.
    origin = tuple(reader.probe_center(scene)[:2])
    room = fit_room(clicks, rotation=rotation, origin=origin, ceiling_height=ceiling_height)
    for name in NAMES:
        obj = bpy.data.objects.get(name)
        if obj is not None and obj.type != 'MESH':
            raise DimredError(f"an object named '{name}' exists and is a {obj.type}, not a mesh: rename it first")
    for mesh in room_meshes(room):
        _put_mesh(scene, mesh)
    set_probe_center(scene, room.probe)
    scene[CLICKS_PROPERTY] = clicks.to_json()
    return room


def stored_clicks(scene: bpy.types.Scene) -> RoomClicks | None:
    """The clicks of the room last matched in `scene`, or None."""
    text = scene.get(CLICKS_PROPERTY)
    return None if text is None else click_file.from_json(str(text))


def set_probe_center(scene: bpy.types.Scene, location: np.ndarray) -> None:
    """Move the probe centre to `location`: the ProbeCenter Empty, and the add-on's setting or the
    scene's probe_center property where the scene uses one."""
    probe = scene.objects.get(reader.PROBE_OBJECT_NAME)
    if probe is None:
        probe = bpy.data.objects.new(reader.PROBE_OBJECT_NAME, None)
        probe.empty_display_type = 'SPHERE'
        probe.empty_display_size = 0.1
        scene.collection.objects.link(probe)
    probe.location = tuple(location)
    settings = getattr(scene, "dimred", None)
    if settings is not None and hasattr(settings, "probe_center"):
        settings.probe_center = tuple(location)
        settings.use_probe_center = True
    elif scene.get("probe_center") is not None:
        scene["probe_center"] = [float(v) for v in location]


def show_panorama(scene: bpy.types.Scene, path: str) -> None:
    """Make the scene's world show the HDR panorama at `path` (a new world, no Mapping node)."""
    try:
        image = bpy.data.images.load(path, check_existing=True)
    except RuntimeError as error:
        raise DimredError(f"cannot load the panorama '{path}': {error}") from None
    world = bpy.data.worlds.new("Panorama")
    if world.node_tree is None:
        world.use_nodes = True  # Blender 4.x creates worlds without a node tree
    tree = world.node_tree
    tree.nodes.clear()
    environment = tree.nodes.new("ShaderNodeTexEnvironment")
    environment.image = image
    background = tree.nodes.new("ShaderNodeBackground")
    output = tree.nodes.new("ShaderNodeOutputWorld")
    tree.links.new(environment.outputs["Color"], background.inputs["Color"])
    tree.links.new(background.outputs["Background"], output.inputs["Surface"])
    scene.world = world


def floor_polygon(scene: bpy.types.Scene) -> np.ndarray | None:
    """(n, 2) world xy of the Floor's outline where the Floor is one polygon (as Match Room
    builds it), else None."""
    floor = scene.objects.get("Floor")
    if floor is None or floor.type != 'MESH' or len(floor.data.polygons) != 1:
        return None
    ring = floor.data.polygons[0].vertices
    return np.array([tuple((floor.matrix_world @ floor.data.vertices[i].co).xy) for i in ring])


def floor_height(scene: bpy.types.Scene) -> float:
    """The z of the Floor object's lowest vertex, 0 where the scene has no Floor mesh."""
    floor = scene.objects.get("Floor")
    if floor is None or floor.type != 'MESH' or not len(floor.data.vertices):
        return 0.0
    return float(min((floor.matrix_world @ v.co).z for v in floor.data.vertices))


def box_object(scene: bpy.types.Scene, name: str, corners: np.ndarray) -> bpy.types.Object:
    """A new box mesh object `name` (or `name`.001 ...) with the 8 `corners` (bottom four counter-
    clockwise, then the top four), its faces' normals outwards."""
    return proxy_object(scene, MeshData(name, np.asarray(corners, dtype=np.float64), _BOX_FACES))


def proxy_object(scene: bpy.types.Scene, data: MeshData) -> bpy.types.Object:
    """A new mesh object named as `data` (or that name.001 ...) of its vertices and faces."""
    obj = bpy.data.objects.new(data.name, _mesh(data))
    scene.collection.objects.link(obj)
    return obj


def reshape_box(obj: bpy.types.Object, corners: np.ndarray) -> None:
    """Give the box proxy `obj` the world `corners` (as `box_object` takes them): a new mesh with
    the old one's materials, the object's transform cleared to the identity."""
    mesh = _mesh(MeshData(obj.data.name, np.asarray(corners, dtype=np.float64), _BOX_FACES))
    old = obj.data
    for material in old.materials:
        mesh.materials.append(material)
    obj.parent = None
    obj.matrix_world = ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (0.0, 0.0, 0.0, 1.0))
    obj.data = mesh
    if old.users == 0:
        bpy.data.meshes.remove(old)


def _mesh(data: MeshData) -> bpy.types.Mesh:
    mesh = bpy.data.meshes.new(data.name)
    mesh.from_pydata([tuple(v) for v in data.vertices.tolist()], [], [list(f) for f in data.faces])
    mesh.validate()
    return mesh


def _put_mesh(scene: bpy.types.Scene, data: MeshData) -> bpy.types.Object:
    mesh = _mesh(data)
    obj = bpy.data.objects.get(data.name)
    if obj is None:
        obj = bpy.data.objects.new(data.name, mesh)
        scene.collection.objects.link(obj)
    else:
        old = obj.data
        for material in old.materials:
            mesh.materials.append(material)
        obj.data = mesh
        obj.matrix_world.identity()
        if old.users == 0:
            bpy.data.meshes.remove(old)
        mesh.name = data.name
        if obj.name not in scene.objects:
            scene.collection.objects.link(obj)
    return obj
