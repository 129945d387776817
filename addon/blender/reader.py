"""Reads a Blender scene into the plain arrays of `SceneData`: the engine's only bpy import.

What Cycles renders is the reference: the panorama is taken in the colour space Blender
renders it in, the Mapping node in front of the Environment Texture becomes the matrix the
lat-long lookup applies, and meshes are read with their modifiers applied.
"""
from __future__ import annotations

import os
from collections.abc import Sequence

import bpy
import numpy as np

from ..errors import DimredError
from ..io.exr import exr_size, read_exr
from ..radiance import row_bands
from ..scene import SceneData

#: Nodes whose name or label starts with this belong to the add-on (the difference layer).
OWN_NODE_PREFIX = "DimRed"
#: The object whose location is the probe centre when the scene does not set one.
PROBE_OBJECT_NAME = "ProbeCenter"

# Object types that evaluate to a mesh; curves and text count only where they have faces.
_GEOMETRY_TYPES = frozenset({"MESH", "CURVE", "SURFACE", "META", "FONT"})
_ENVIRONMENT = "ShaderNodeTexEnvironment"
# Colour passes straight through these from the Environment Texture to the World Output.
_PASS_THROUGH = {
    "ShaderNodeBackground": ("Color",),
    "ShaderNodeAddShader": (0, 1),
    "ShaderNodeMixShader": (1, 2),
    "ShaderNodeMixRGB": ("Color1", "Color2"),
}
# Blend modes of a colour Mix node that keep the panorama as it is where it is shown.
_PASS_THROUGH_BLENDS = frozenset({"MIX", "ADD"})
# Outputs of the Texture Coordinate node that are the view direction in a world shader.
_DIRECTION_OUTPUTS = frozenset({"Generated", "Object"})


def read_scene(scene: bpy.types.Scene, center: Sequence[float] | None = None, *,
               exclude: Sequence[str] = (), defer_file: bool = False) -> SceneData:
    """Everything the engine needs from `scene`, as numpy arrays in world space.

    center overrides the probe centre the scene defines (see `probe_center`). Objects named in
    `exclude` are left out of the geometry (objects already removed from the panorama). With
    `defer_file`, a panorama that can be read straight from its EXR file is not read here:
    `hdri` is None and `hdri_path` names the file (`addon.run.job.loaded` reads it later), which
    keeps Blender's main thread free of the file's decoding.
    """
    notes: list[str] = []
    # Transforms set since the last update (a script that just placed the probe Empty) are not
    # in matrix_world yet; evaluate the view layer first.
    _view_layer(scene).update()
    node = environment_texture(scene)
    rotation = texture_rotation(node)
    hdri, path = _panorama(node.image, notes, defer_file)
    centre = probe_center(scene, center, notes=notes)
    triangles, tri_object, names = _geometry(scene, notes, frozenset(exclude))
    return SceneData(
        hdri=hdri,
        rotation=rotation,
        center=centre,
        triangles=triangles,
        tri_object=tri_object,
        object_names=names,
        hdri_path=path,
        notes=notes,
    )


def check_object(scene: bpy.types.Scene, name: str, *, purpose: str = "removed") -> None:
    """DimredError unless `name` is a render-visible mesh of `scene`.

    purpose completes "only mesh objects can be ..." in the message.
    """
    obj = scene.objects.get(name)
    if obj is None:
        raise DimredError(f"no object named '{name}' in scene '{scene.name}'")
    if obj.type != "MESH":
        raise DimredError(f"'{name}' is a {obj.type}, not a mesh: only mesh objects can be {purpose}")
    if obj not in _render_visible_objects(scene):
        raise DimredError(f"'{name}' is hidden for render, so it is not in the scene's geometry: make it visible first")


def panorama_size(scene: bpy.types.Scene) -> tuple[int, int]:
    """(width, height) of the panorama `read_scene` reads, without reading its pixels where it
    reads them from an EXR file (the file's header), else from the image Blender loads: what
    `memory.check_fits` needs before a run starts."""
    image = environment_texture(scene).image
    path = _image_path(image)
    if _is_exact_file(image, path):
        return exr_size(path)
    return _loaded_size(image, path)


def panorama_pixels(scene: bpy.types.Scene) -> np.ndarray:
    """The panorama's (H, W, 3) float32 linear RGB, top row first, as `read_scene` reads it."""
    return _panorama(environment_texture(scene).image, [])[0]


def panorama_file(scene: bpy.types.Scene) -> str:
    """The file the panorama is read from; "" when its pixels are in the .blend (packed or
    generated): what a batch hashes besides the .blend to tell whether a job's input changed."""
    image = environment_texture(scene).image
    path = _image_path(image)
    return "" if image.packed_file is not None else path


def environment_texture(scene: bpy.types.Scene) -> bpy.types.ShaderNodeTexEnvironment:
    """The Environment Texture node whose image the active World Output shows.

    Nodes named or labelled DimRed... (the add-on's own difference layer) are not candidates.
    """
    world = scene.world
    if world is None:
        raise DimredError(f"scene '{scene.name}' has no world: add a World with an Environment Texture holding "
                          "the HDR panorama")
    # World.use_nodes is deprecated from Blender 5.0 on, where world shading always uses nodes.
    if world.node_tree is None or (bpy.app.version < (5, 0, 0) and not world.use_nodes):
        raise DimredError(f"world '{world.name}' does not use nodes: turn on Use Nodes and add an Environment "
                          "Texture with the panorama")
    output = world.node_tree.get_output_node("CYCLES")
    if output is None:
        raise DimredError(f"world '{world.name}' has no active World Output node")
    found: list[bpy.types.Node] = []
    _collect_environments(output.inputs["Surface"], found)
    if not found:
        raise DimredError(
            f"world '{world.name}' shows no Environment Texture: connect one holding the HDR panorama to the Background"
        )
    first = found[0]
    for other in found[1:]:
        if other.image != first.image or not np.allclose(texture_rotation(other), texture_rotation(first)):
            raise DimredError(
                f"world '{world.name}' mixes several panoramas ('{first.name}', '{other.name}'): "
                "keep one Environment Texture, the one photographed from the probe centre"
            )
    if first.image is None:
        raise DimredError(f"Environment Texture '{first.name}' in world '{world.name}' has no image")
    if first.projection != "EQUIRECTANGULAR":
        raise DimredError(
            f"Environment Texture '{first.name}' uses {first.projection} projection: only equirectangular "
            "panoramas are supported"
        )
    return first


def texture_rotation(node: bpy.types.ShaderNodeTexEnvironment) -> np.ndarray:
    """(3, 3) matrix M such that the world direction d samples the texture at M @ d.

    Identity without a Mapping node. A Mapping node's Euler XYZ rotation R (R = Rz Ry Rx,
    mathutils' convention) gives M = R S for types Point, Vector and Normal and M = S R^T for
    Texture (its inverse), where S = diag(sign(scale)). The lookup normalises the vector, so
    only the scale's signs (mirroring) matter; location does not move a direction.
    Non-uniform scale would bend the panorama and is refused.
    """
    source = _linked_output(node.inputs["Vector"])
    if source is None:
        return np.eye(3)
    if source.node.bl_idname == "ShaderNodeTexCoord" and source.name in _DIRECTION_OUTPUTS:
        _check_direction_output(source, node)
        return np.eye(3)
    if source.node.bl_idname != "ShaderNodeMapping":
        raise DimredError(
            f"the vector of Environment Texture '{node.name}' comes from '{source.node.name}': "
            "only a Mapping node (or nothing) is supported there"
        )
    mapping = source.node
    for socket_name in ("Rotation", "Scale"):
        if mapping.inputs[socket_name].is_linked:
            raise DimredError(f"Mapping node '{mapping.name}' has its {socket_name} driven by a link: "
                              "set it as a value")
    vector = _linked_output(mapping.inputs["Vector"])
    if vector is None:
        # Cycles then maps the constant (0, 0, 0): the whole world shows one texel.
        raise DimredError(
            f"Mapping node '{mapping.name}' has nothing connected to its Vector input: "
            "connect Texture Coordinate > Generated"
        )
    if vector.node.bl_idname != "ShaderNodeTexCoord" or vector.name not in _DIRECTION_OUTPUTS:
        raise DimredError(
            f"Mapping node '{mapping.name}' takes its vector from '{vector.node.name}' > {vector.name}: "
            "only Texture Coordinate > Generated is supported"
        )
    _check_direction_output(vector, node)
    scale = np.array(mapping.inputs["Scale"].default_value, dtype=np.float64)
    magnitude = np.abs(scale)
    if magnitude.min() == 0.0 or not np.allclose(magnitude, magnitude[0], rtol=1e-6, atol=0.0):
        raise DimredError(
            f"Mapping node '{mapping.name}' scales by {_format(scale)}: "
            "only uniform scale or mirroring (-1) keeps a panorama undistorted"
        )
    mirror = np.diag(np.sign(scale))
    rotation = np.array(mapping.inputs["Rotation"].default_value.to_matrix(), dtype=np.float64)
    if mapping.vector_type == "TEXTURE":
        return mirror @ rotation.T
    return rotation @ mirror


def probe_center(scene: bpy.types.Scene, center: Sequence[float] | None = None, *,
                 notes: list[str] | None = None) -> np.ndarray:
    """(3,) probe centre: `center`, else the scene's probe_center, else ProbeCenter, else origin.

    The scene's value is the add-on setting `scene.dimred.probe_center` when switched on by
    `use_probe_center` (read from the saved data when the add-on is not registered), else a
    custom property `probe_center` on the scene. Which source was used is appended to notes.
    """
    notes = [] if notes is None else notes
    if center is not None:
        value = _vector3(center, "the probe centre given")
        notes.append(f"probe centre {_format(value)} as given")
        return value
    stored = _stored_probe_center(scene)
    if stored is not None:
        value = _vector3(stored[0], stored[1])
        notes.append(f"probe centre {_format(value)} from {stored[1]}")
        return value
    obj = scene.objects.get(PROBE_OBJECT_NAME)
    if obj is not None:
        value = np.array(obj.matrix_world.translation, dtype=np.float64)
        notes.append(f"probe centre {_format(value)} from object '{PROBE_OBJECT_NAME}'")
        return value
    notes.append("probe centre at the world origin (no probe_center property, no 'ProbeCenter' object)")
    return np.zeros(3)


def _collect_environments(socket: bpy.types.NodeSocket, found: list[bpy.types.Node]) -> None:
    """Append the Environment Textures whose colour reaches `socket` (depth first, in order)."""
    source = _linked_output(socket)
    if source is None:
        return
    node = source.node
    if node.bl_idname == _ENVIRONMENT:
        if not _is_own(node) and node not in found:
            found.append(node)
        return
    inputs = _colour_inputs(node)
    if inputs is None:
        behind: list[bpy.types.Node] = []
        for other in node.inputs:
            _collect_environments(other, behind)
        if behind:
            raise DimredError(
                f"the world's panorama passes through node '{node.name}' ({node.bl_label}), which changes it: "
                "connect the Environment Texture straight to the Background"
            )
        return
    for other in inputs:
        _collect_environments(other, found)


def _colour_inputs(node: bpy.types.Node) -> list[bpy.types.NodeSocket] | None:
    """The inputs that carry the panorama unchanged through `node`, None for any other node."""
    if node.bl_idname in ("ShaderNodeMix", "ShaderNodeMixRGB") and node.blend_type not in _PASS_THROUGH_BLENDS:
        return None
    if node.bl_idname == "ShaderNodeMix":
        return [s for s in node.inputs if s.type == "RGBA" and s.enabled] if node.data_type == "RGBA" else None
    keys = _PASS_THROUGH.get(node.bl_idname)
    return None if keys is None else [node.inputs[key] for key in keys]


def _linked_output(socket: bpy.types.NodeSocket) -> bpy.types.NodeSocket | None:
    """The output socket feeding `socket`, looking through reroutes, muted links and muted
    nodes (which pass their input through, as Blender shows them)."""
    links = [link for link in socket.links if not link.is_muted and link.is_valid]
    if not links:
        return None
    source = links[0].from_socket
    if source.node.bl_idname == "NodeReroute":
        return _linked_output(source.node.inputs[0])
    if source.node.mute:
        passed = [link.from_socket for link in source.node.internal_links if link.to_socket == source]
        return _linked_output(passed[0]) if passed else None
    return source


def _check_direction_output(source: bpy.types.NodeSocket, node: bpy.types.Node) -> None:
    if source.name == "Object" and source.node.object is not None:
        raise DimredError(
            f"the Texture Coordinate feeding '{node.name}' uses object '{source.node.object.name}': "
            "use Generated, or clear the object"
        )


def _is_own(node: bpy.types.Node) -> bool:
    return node.name.startswith(OWN_NODE_PREFIX) or node.label.startswith(OWN_NODE_PREFIX)


def _panorama(image: bpy.types.Image, notes: list[str], defer_file: bool = False) -> tuple[np.ndarray | None, str]:
    """(H, W, 3) float32 linear RGB, top row first, as Cycles renders `image`; and its path.

    With `defer_file`, None instead of the pixels when they are exactly the EXR file's."""
    path = _image_path(image)
    if _is_exact_file(image, path):
        # Blender's buffer holds the same values; the file is read to skip Blender's image cache.
        return (None if defer_file else read_exr(path)), path
    colour = image.colorspace_settings
    width, height = _loaded_size(image, path)
    if image.is_float:
        if not colour.is_data and not _is_linear(colour.name):
            notes.append(
                f"image '{image.name}' is tagged '{colour.name}', a non-linear colour space unusual for HDR data; "
                "it was linearised as Blender renders it (set Linear Rec.709 if the file holds linear radiance)"
            )
        return _blender_rgb(image, width, height), path
    # Blender hands out 8-bit images as stored (code value / 255), without colour management.
    if colour.name != "sRGB" and not colour.is_data and not _is_linear(colour.name):
        raise DimredError(
            f"8-bit image '{image.name}' is in colour space '{colour.name}', which cannot be linearised here: "
            "use an HDR file (EXR, HDR) or set sRGB"
        )
    notes.append(f"image '{image.name}' is 8-bit, not HDR: light sources in it are clipped")
    rgb = _blender_rgb(image, width, height)
    if colour.name == "sRGB":
        _srgb_to_linear(rgb)
    return rgb, path


def _image_path(image: bpy.types.Image) -> str:
    """The file `image` comes from ("" for a generated image); DimredError for a source the
    engine cannot read or a file that is not there."""
    if image.source not in ("FILE", "GENERATED"):
        raise DimredError(f"image '{image.name}' is a {image.source.lower()} image: use a single panorama file")
    if image.source == "GENERATED":
        return ""
    path = os.path.normpath(bpy.path.abspath(image.filepath, library=image.library))
    if image.packed_file is None and not os.path.isfile(path):
        raise DimredError(f"cannot load image '{image.name}': file not found: {path}")
    return path


def _loaded_size(image: bpy.types.Image, path: str) -> tuple[int, int]:
    """(width, height) of the pixels Blender holds for `image` (asking loads them)."""
    count = len(image.pixels)
    width, height = image.size
    if count == 0 or width * height == 0:
        if image.source == "FILE" and image.packed_file is None:
            raise DimredError(f"cannot load image '{image.name}' from {path}: Blender cannot read the file")
        raise DimredError(f"image '{image.name}' has no pixels")
    return width, height


def _blender_rgb(image: bpy.types.Image, width: int, height: int) -> np.ndarray:
    """(H, W, 3) float32 of Blender's pixels for `image`, top row first, in the one array they
    are copied into: each pixel's colour is moved to the front of the RGBA buffer and the buffer
    shrunk to it, and the rows (Blender's start at the bottom) are swapped, all in place."""
    flat = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(flat)
    channels = flat.size // (width * height)
    if channels < 3:
        # Grey: the RGB image is larger than Blender's buffer.
        rgb = np.repeat(flat.reshape(height, width, channels)[..., :1], 3, axis=2)
    else:
        if channels > 3:
            _pack_rgb(flat, width, height, channels)
            # No view of `flat` outlives _pack_rgb, so numpy's check for views, which miscounts
            # references under a debugger, is left out. Shrinking gives the tail back in place.
            flat.resize(height * width * 3, refcheck=False)
        rgb = flat.reshape(height, width, 3)
    _flip_rows(rgb)
    return rgb


def _pack_rgb(flat: np.ndarray, width: int, height: int, channels: int) -> None:
    """Move each pixel's first three of `channels` values to the front of `flat`, in place.

    A band's colour lands where only that band and earlier ones lay, so going from the start
    overwrites nothing still to be read (numpy buffers a band that overlaps its destination).
    """
    for start, stop in row_bands(height, width):
        source = flat[start * width * channels:stop * width * channels].reshape(stop - start, width, channels)
        flat[start * width * 3:stop * width * 3].reshape(stop - start, width, 3)[...] = source[..., :3]


def _flip_rows(rgb: np.ndarray) -> None:
    """Reverse the order of the rows of `rgb` in place, a band from each end at a time."""
    height, width = rgb.shape[:2]
    for start, stop in row_bands(height // 2, width):
        top = rgb[start:stop].copy()
        rgb[start:stop] = rgb[height - stop:height - start][::-1]
        rgb[height - stop:height - start] = top[::-1]


def _is_exact_file(image: bpy.types.Image, path: str) -> bool:
    """Whether the EXR on disk holds exactly what Blender renders (no colour conversion)."""
    if image.source != "FILE" or image.packed_file is not None or image.is_dirty:
        return False
    if not path.lower().endswith(".exr"):
        return False
    colour = image.colorspace_settings
    return colour.is_data or colour.name in {_working_space(), "scene_linear"}


def _working_space() -> str:
    """Blender's scene-linear colour space: per file from 5.0 on, Linear Rec.709 before."""
    settings = getattr(bpy.data, "colorspace", None)
    return settings.working_space if settings is not None else "Linear Rec.709"


def _is_linear(name: str) -> bool:
    return name.startswith("Linear") or name in {"scene_linear", "ACEScg", "ACES2065-1", "Non-Color", "Raw"}


def _srgb_to_linear(rgb: np.ndarray) -> None:
    """Decode the sRGB code values in `rgb` in place, band by band, with the sRGB transfer
    function (IEC 61966-2-1), as Blender's "sRGB" colour space decodes."""
    height, width = rgb.shape[:2]
    for start, stop in row_bands(height, width):
        band = rgb[start:stop]
        band[...] = np.where(band <= 0.04045, band / 12.92, ((band + 0.055) / 1.055) ** 2.4)


def _stored_probe_center(scene: bpy.types.Scene) -> tuple[object, str] | None:
    """The probe centre the scene stores, with a description of where, or None."""
    settings = getattr(scene, "dimred", None)
    if settings is not None and hasattr(settings, "probe_center"):
        switched_on = getattr(settings, "use_probe_center", None)
        if switched_on is None:
            switched_on = settings.is_property_set("probe_center")
        if switched_on:
            return tuple(settings.probe_center), "scene.dimred.probe_center"
    elif (stored := _unregistered_settings(scene)) is not None:
        if stored.get("use_probe_center") and stored.get("probe_center") is not None:
            return stored["probe_center"], "the saved add-on setting probe_center"
    if scene.get("probe_center") is not None:
        return scene["probe_center"], "scene property 'probe_center'"
    return None


def _unregistered_settings(scene: bpy.types.Scene) -> object | None:
    """The add-on's saved `scene.dimred` values when the add-on is not registered (the
    command line run by plain Python). Blender 5 stores add-on properties apart from custom
    properties, reachable only through bl_system_properties_get; 4.x among them."""
    system = getattr(scene, "bl_system_properties_get", None)
    for group in (system(do_create=False) if system is not None else None, scene):
        stored = group.get("dimred") if group is not None else None
        if stored is not None and hasattr(stored, "get"):
            return stored
    return None


def _vector3(value: object, what: str) -> np.ndarray:
    try:
        vector = np.array([float(x) for x in value], dtype=np.float64)  # type: ignore[union-attr]
    except (TypeError, ValueError):
        raise DimredError(f"{what} must be three numbers, got {value!r}") from None
    if vector.shape != (3,) or not np.all(np.isfinite(vector)):
        raise DimredError(f"{what} must be three finite numbers, got {tuple(vector)}")
    return vector


def _format(value: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.6g}" for x in value) + ")"


def _render_visible_objects(scene: bpy.types.Scene) -> set[bpy.types.Object]:
    """Objects Cycles renders in the active view layer: not hidden for render, in a collection
    that is neither excluded from the view layer nor hidden for render (nor below one that is)."""
    visible: set[int] = set()
    stack = [_view_layer(scene).layer_collection]
    while stack:
        layer = stack.pop()
        if layer.exclude or layer.collection.hide_render:
            continue
        visible.add(layer.collection.as_pointer())
        stack.extend(layer.children)
    return {
        obj
        for obj in scene.objects
        if not obj.hide_render and any(c.as_pointer() in visible for c in obj.users_collection)
    }


def _view_layer(scene: bpy.types.Scene) -> bpy.types.ViewLayer:
    context_layer = bpy.context.view_layer
    if bpy.context.scene == scene and context_layer is not None:
        return context_layer
    return scene.view_layers[0]


def _geometry(scene: bpy.types.Scene, notes: list[str],
              exclude: frozenset[str] = frozenset()) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """World-space triangles of every render-visible object that evaluates to a mesh, except `exclude`."""
    visible = sorted((obj for obj in _render_visible_objects(scene) if obj.name not in exclude),
                     key=lambda obj: obj.name)
    depsgraph = _view_layer(scene).depsgraph
    names: list[str] = []
    chunks: list[np.ndarray] = []
    owners: list[np.ndarray] = []
    for obj in visible:
        if obj.type not in _GEOMETRY_TYPES:
            continue
        evaluated = obj.evaluated_get(depsgraph)
        if not evaluated.is_evaluated:
            notes.append(f"'{obj.name}' is disabled in viewports, so its modifiers were not applied")
        triangles = _object_triangles(evaluated)
        if obj.type != "MESH" and len(triangles) == 0:
            continue
        chunks.append(triangles)
        owners.append(np.full(len(triangles), len(names), dtype=np.int32))
        names.append(obj.name)
        notes.extend(_modifier_notes(obj))
    lights = [obj.name for obj in visible if obj.type == "LIGHT"]
    if lights:
        notes.append(
            f"{len(lights)} light object(s) ({', '.join(lights)}) are not geometry and are ignored: "
            "model each real lamp as an emitting mesh"
        )
    instancers = sorted({inst.parent.name for inst in depsgraph.object_instances if inst.is_instance and inst.parent})
    if instancers:
        notes.append(f"instanced geometry of {', '.join(instancers)} is ignored: make the instances real to include it")
    if not chunks:
        return np.zeros((0, 3, 3)), np.zeros(0, dtype=np.int32), names
    return np.concatenate(chunks), np.concatenate(owners), names


def _object_triangles(evaluated: bpy.types.Object) -> np.ndarray:
    """(T, 3, 3) float64 world-space triangles of an evaluated object's mesh."""
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        coords = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", coords)
        corners = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", corners)
    finally:
        evaluated.to_mesh_clear()
    matrix = np.array(evaluated.matrix_world, dtype=np.float64)
    world = coords.reshape(-1, 3).astype(np.float64) @ matrix[:3, :3].T + matrix[:3, 3]
    triangles = world[corners.reshape(-1, 3)]
    if np.linalg.det(matrix[:3, :3]) < 0.0:
        # A mirroring transform flips the winding; restore it so normals keep facing out.
        triangles = triangles[:, ::-1]
    return triangles


def _modifier_notes(obj: bpy.types.Object) -> list[str]:
    """Where the viewport evaluation read here differs from what Cycles renders."""
    notes = []
    for modifier in obj.modifiers:
        if modifier.show_viewport != modifier.show_render:
            state = "on in the viewport, off" if modifier.show_viewport else "off in the viewport, on"
            notes.append(f"'{obj.name}': modifier '{modifier.name}' is {state} in renders; the viewport state was used")
        elif getattr(modifier, "render_levels", None) not in (None, getattr(modifier, "levels", None)):
            notes.append(
                f"'{obj.name}': modifier '{modifier.name}' has viewport levels {modifier.levels}, "
                f"render levels {modifier.render_levels}; the viewport levels were used"
            )
    return notes
