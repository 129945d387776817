"""The reader from Blender to `SceneData`: evaluated world-space geometry, the panorama's pixels
in the order and colour space Cycles uses, the probe centre's precedence, and one clear error
per kind of bad scene."""
from __future__ import annotations

import math
from types import SimpleNamespace

import bpy
import numpy as np
import pytest

from addon import radiance
from addon.blender import reader
from addon.errors import DimredError
from addon.geometry import latlong
from addon.io.exr import write_exr, write_png

pytestmark = pytest.mark.usefixtures("fresh_blender")

TOP = np.array([0.9, 0.1, 0.2], np.float32)


@pytest.fixture
def panorama_file(tmp_path):
    """An 8 x 4 EXR whose top row is TOP and the rest dark grey: (path, pixels)."""
    pixels = np.full((4, 8, 3), 0.05, np.float32)
    pixels[0] = TOP
    pixels[3, 5] = [4.0, 5.0, 6.0]
    path = tmp_path / "probe.exr"
    write_exr(path, pixels)
    return path, pixels


@pytest.fixture
def world(panorama_world, panorama_file):
    """The scene's world showing the panorama file; returns its node tree."""
    return panorama_world(bpy.data.images.load(str(panorama_file[0])))


def _cube(name: str, location=(0.0, 0.0, 0.0)) -> bpy.types.Object:
    mesh = bpy.data.meshes.new(name)
    corners = [(x, y, z) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    faces = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    mesh.from_pydata(corners, [], faces)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _triangles_of(data, name: str) -> np.ndarray:
    return data.triangles[data.tri_object == data.object_index(name)]


# --- geometry -------------------------------------------------------------------------------


def test_modifiers_are_applied_and_positions_are_in_world_space(world):
    obj = _cube("Shelf")
    array = obj.modifiers.new("Array", 'ARRAY')
    array.count = 3  # relative offset 1: copies 2 m apart along local X
    obj.location = (1.0, 2.0, 3.0)
    obj.rotation_euler = (0.0, 0.0, math.radians(90.0))
    obj.scale = (2.0, 1.0, 0.5)
    data = reader.read_scene(bpy.context.scene)
    triangles = _triangles_of(data, "Shelf")
    assert data.triangles.dtype == np.float64 and data.triangles.shape[1:] == (3, 3)
    assert len(triangles) == 3 * 12
    local = np.array([(x + 2 * k, y, z) for k in range(3) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], float)
    # scale, then rotate +90 degrees about Z (x -> y, y -> -x), then move
    scaled = local * [2.0, 1.0, 0.5]
    expected = np.stack([-scaled[:, 1], scaled[:, 0], scaled[:, 2]], axis=1) + np.array([1.0, 2.0, 3.0])
    corners = triangles.reshape(-1, 3)
    distance = np.linalg.norm(corners[:, None] - expected[None], axis=-1)
    assert distance.min(axis=1).max() < 1e-5  # every triangle corner is an expected vertex
    assert distance.min(axis=0).max() < 1e-5  # every expected vertex is used


def test_subdivision_gives_the_evaluated_triangle_count(world):
    obj = _cube("Rock")
    subdivision = obj.modifiers.new("Subdivision", 'SUBSURF')
    subdivision.levels = 2
    subdivision.render_levels = 2
    data = reader.read_scene(bpy.context.scene)
    assert len(_triangles_of(data, "Rock")) == 6 * 16 * 2
    assert not any("viewport levels" in note for note in data.notes)
    subdivision.render_levels = 3
    notes = reader.read_scene(bpy.context.scene).notes
    assert any("'Rock': modifier 'Subdivision' has viewport levels 2, render levels 3" in n for n in notes)


def test_mirrored_objects_keep_outward_winding(world):
    for name, scale in (("Plain", (1.0, 1.0, 1.0)), ("Mirrored", (-1.0, 1.0, 1.0))):
        _cube(name, location=(5.0 * len(name), 0.0, 0.0)).scale = scale
    data = reader.read_scene(bpy.context.scene)
    for name in ("Plain", "Mirrored"):
        triangles = _triangles_of(data, name)
        normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
        outward = triangles.mean(axis=1) - triangles.reshape(-1, 3).mean(axis=0)
        assert np.all(np.einsum("ij,ij->i", normals, outward) > 0), name


def test_only_render_visible_geometry(world):
    scene = bpy.context.scene
    _cube("Visible")
    _cube("HiddenForRender").hide_render = True
    _cube("HiddenInViewport").hide_set(True)  # the eye: renders anyway
    hidden_collection = bpy.data.collections.new("Stash")
    scene.collection.children.link(hidden_collection)
    hidden_collection.hide_render = True
    excluded = bpy.data.collections.new("Excluded")
    scene.collection.children.link(excluded)
    bpy.context.view_layer.layer_collection.children["Excluded"].exclude = True
    for collection, name in ((hidden_collection, "InHiddenCollection"), (excluded, "InExcludedCollection")):
        obj = _cube(name)
        scene.collection.objects.unlink(obj)
        collection.objects.link(obj)
    lamp = bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", 'AREA'))
    scene.collection.objects.link(lamp)
    scene.collection.objects.link(bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera")))
    scene.collection.objects.link(bpy.data.objects.new("Marker", None))
    data = reader.read_scene(scene)
    assert data.object_names == ["HiddenInViewport", "Visible"]
    assert data.tri_object.shape == (24,) and set(data.tri_object.tolist()) == {0, 1}
    assert any("1 light object(s) (Lamp)" in note for note in data.notes)


def test_curves_count_only_with_faces(world):
    scene = bpy.context.scene
    for name, bevel in (("Pipe", 0.1), ("Wire", 0.0)):
        curve = bpy.data.curves.new(name, 'CURVE')
        curve.dimensions = '3D'
        spline = curve.splines.new('POLY')
        spline.points.add(1)
        spline.points[1].co = (1.0, 0.0, 0.0, 1.0)
        curve.bevel_depth = bevel
        scene.collection.objects.link(bpy.data.objects.new(name, curve))
    data = reader.read_scene(scene)
    assert data.object_names == ["Pipe"] and len(data.triangles) > 0


def test_scene_without_geometry(world):
    data = reader.read_scene(bpy.context.scene)
    assert data.triangles.shape == (0, 3, 3) and data.tri_object.shape == (0,) and data.object_names == []


# --- the panorama ---------------------------------------------------------------------------


def test_exr_panorama_is_read_top_row_first(world, panorama_file):
    path, pixels = panorama_file
    data = reader.read_scene(bpy.context.scene)
    assert data.hdri.dtype == np.float32
    np.testing.assert_array_equal(data.hdri, pixels)
    np.testing.assert_array_equal(data.hdri[0], np.broadcast_to(TOP, (8, 3)))
    assert data.hdri_path == str(path)
    np.testing.assert_array_equal(data.rotation, np.eye(3))


def test_blender_pixels_are_flipped_to_top_row_first(world, panorama_file):
    """A packed image is read through Image.pixels, which start at the bottom-left."""
    image = world.nodes["Environment Texture"].image
    image.pack()
    np.testing.assert_array_equal(reader.read_scene(bpy.context.scene).hdri, panorama_file[1])


def test_generated_image_pixels(panorama_world):
    image = bpy.data.images.new("painted", 4, 2, float_buffer=True)
    blender_rows = np.zeros((2, 4, 4), np.float32)  # bottom row first, RGBA
    blender_rows[1, :, :3] = TOP
    blender_rows[..., 3] = 1.0
    image.pixels.foreach_set(blender_rows.ravel())
    panorama_world(image)
    hdri = reader.read_scene(bpy.context.scene).hdri
    assert hdri.shape == (2, 4, 3)
    np.testing.assert_array_equal(hdri[0], np.broadcast_to(TOP, (4, 3)))
    np.testing.assert_array_equal(hdri[1], 0.0)


class _Pixels:
    """Image.pixels as a buffer of `values`, bottom row first."""

    def __init__(self, values: np.ndarray):
        self.values = values

    def __len__(self) -> int:
        return self.values.size

    def foreach_get(self, out: np.ndarray) -> None:
        out[...] = self.values


@pytest.mark.parametrize("channels", [4, 3, 1])
def test_blender_pixels_over_several_bands(monkeypatch, channels):
    """Colour packed to the front and rows swapped in place, band by band: odd sizes, and each
    buffer layout an image may have."""
    monkeypatch.setattr(radiance, "_BAND_PIXELS", 10)  # one or two rows a band
    width, height = 7, 5
    texels = np.random.default_rng(2).random((height, width, channels)).astype(np.float32)
    image = SimpleNamespace(pixels=_Pixels(texels[::-1].ravel()))
    expected = texels[..., :3] if channels >= 3 else np.repeat(texels, 3, axis=2)
    np.testing.assert_array_equal(reader._blender_rgb(image, width, height), expected)


def test_blender_pixels_are_copied_once(monkeypatch):
    """The RGB image is the very buffer Blender's RGBA pixels were copied into, shrunk."""
    monkeypatch.setattr(radiance, "_BAND_PIXELS", 256)
    pixels = _Pixels(np.random.default_rng(3).random(128 * 256 * 4).astype(np.float32))
    buffers = []
    copy_into = pixels.foreach_get

    def foreach_get(out):
        buffers.append(out.ctypes.data)
        copy_into(out)

    pixels.foreach_get = foreach_get
    rgb = reader._blender_rgb(SimpleNamespace(pixels=pixels), 256, 128)
    assert rgb.ctypes.data == buffers[0] and rgb.base.nbytes == rgb.nbytes


def test_panorama_size_of_an_exr_file_comes_from_its_header(world, monkeypatch):
    def pixels_read(path):
        raise AssertionError(f"the pixels of {path} were read")

    monkeypatch.setattr(reader, "read_exr", pixels_read)
    assert reader.panorama_size(bpy.context.scene) == (8, 4)
    assert not world.nodes["Environment Texture"].image.has_data


def test_panorama_size_of_a_blender_image(panorama_world):
    panorama_world(bpy.data.images.new("painted", 32, 16, float_buffer=True))
    assert reader.panorama_size(bpy.context.scene) == (32, 16)


def test_non_linear_colour_space_is_converted_as_blender_does_and_noted(world, panorama_file):
    image = world.nodes["Environment Texture"].image
    image.colorspace_settings.name = "sRGB"
    data = reader.read_scene(bpy.context.scene)
    expected = np.empty(len(image.pixels), np.float32)
    image.pixels.foreach_get(expected)
    np.testing.assert_array_equal(data.hdri, expected.reshape(4, 8, 4)[::-1, :, :3])
    assert not np.allclose(data.hdri, panorama_file[1])
    assert any("tagged 'sRGB', a non-linear colour space" in note for note in data.notes)


def test_eight_bit_srgb_image_is_linearised(panorama_world, tmp_path):
    codes = np.array([0, 10, 128, 255], np.uint8)
    write_png(tmp_path / "ldr.png", np.repeat(codes[None, :, None], 3, axis=2))
    panorama_world(bpy.data.images.load(str(tmp_path / "ldr.png")))
    data = reader.read_scene(bpy.context.scene)
    c = codes / 255.0
    expected = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
    np.testing.assert_allclose(data.hdri[0, :, 0], expected, rtol=1e-6)
    assert any("8-bit, not HDR" in note for note in data.notes)


@pytest.mark.slow
@pytest.mark.parametrize("kind", ["sRGB-tagged EXR", "8-bit sRGB PNG"])
def test_colour_handling_matches_cycles(panorama_world, render_world, tmp_path, kind):
    """What the reader reads is what Cycles shows, also where colour management converts."""
    texels = np.random.default_rng(5).random((8, 16, 3)).astype(np.float32)
    if kind == "8-bit sRGB PNG":
        write_png(tmp_path / "ldr.png", (texels * 255).astype(np.uint8))
        image = bpy.data.images.load(str(tmp_path / "ldr.png"))
    else:
        write_exr(tmp_path / "tagged.exr", texels)
        image = bpy.data.images.load(str(tmp_path / "tagged.exr"))
        image.colorspace_settings.name = "sRGB"
    panorama_world(image)
    hdri = reader.read_scene(bpy.context.scene).hdri
    render = render_world(16, 8)
    np.testing.assert_allclose(render, hdri, rtol=1e-3, atol=1e-6)


def test_mapping_node_gives_the_rotation(panorama_world, panorama_file):
    angles = (math.radians(10.0), math.radians(-20.0), math.radians(40.0))
    panorama_world(bpy.data.images.load(str(panorama_file[0])), ("POINT", angles, (3.0, 3.0, 3.0)))
    data = reader.read_scene(bpy.context.scene)
    from mathutils import Euler

    np.testing.assert_allclose(data.rotation, np.array(Euler(angles, 'XYZ').to_matrix()), atol=1e-7)
    u, v = latlong.direction_to_uv(np.array([0.0, 0.0, 1.0]), data.rotation)
    assert 0.0 <= u <= 1.0 and 0.0 <= v <= 1.0


def test_our_difference_layer_is_ignored(world, panorama_file):
    tree = world
    nodes, links = tree.nodes, tree.links
    difference = nodes.new("ShaderNodeTexEnvironment")
    difference.name = "DimRed Difference"
    difference.image = bpy.data.images.new("difference", 8, 4, float_buffer=True)
    add = nodes.new("ShaderNodeMix")
    add.data_type = 'RGBA'
    add.blend_type = 'ADD'
    add.inputs["Factor"].default_value = 1.0
    links.new(nodes["Environment Texture"].outputs["Color"], add.inputs["A"])
    links.new(difference.outputs["Color"], add.inputs["B"])
    links.new(add.outputs["Result"], nodes["Background"].inputs["Color"])
    np.testing.assert_array_equal(reader.read_scene(bpy.context.scene).hdri, panorama_file[1])


def test_same_panorama_for_camera_and_lighting_is_accepted(world, panorama_file):
    """A Light Path mix of two Backgrounds showing the same image is one panorama."""
    nodes, links = world.nodes, world.links
    second = nodes.new("ShaderNodeTexEnvironment")
    second.image = nodes["Environment Texture"].image
    background = nodes.new("ShaderNodeBackground")
    mix = nodes.new("ShaderNodeMixShader")
    light_path = nodes.new("ShaderNodeLightPath")
    links.new(second.outputs["Color"], background.inputs["Color"])
    links.new(light_path.outputs["Is Camera Ray"], mix.inputs[0])
    links.new(nodes["Background"].outputs["Background"], mix.inputs[1])
    links.new(background.outputs["Background"], mix.inputs[2])
    links.new(mix.outputs["Shader"], nodes["World Output"].inputs["Surface"])
    np.testing.assert_array_equal(reader.read_scene(bpy.context.scene).hdri, panorama_file[1])
    second.image = bpy.data.images.new("other", 8, 4, float_buffer=True)
    with pytest.raises(DimredError, match="mixes several panoramas"):
        reader.read_scene(bpy.context.scene)


# --- probe centre ---------------------------------------------------------------------------


class _Settings(bpy.types.PropertyGroup):
    """The part of the add-on's scene.dimred that the reader reads."""

    probe_center: bpy.props.FloatVectorProperty(size=3)
    use_probe_center: bpy.props.BoolProperty()


@pytest.fixture
def settings_registered():
    bpy.utils.register_class(_Settings)
    bpy.types.Scene.dimred = bpy.props.PointerProperty(type=_Settings)
    yield
    del bpy.types.Scene.dimred
    bpy.utils.unregister_class(_Settings)


def test_probe_centre_precedence(world, settings_registered):
    scene = bpy.context.scene
    assert reader.probe_center(scene).tolist() == [0.0, 0.0, 0.0]
    empty = bpy.data.objects.new("ProbeCenter", None)
    scene.collection.objects.link(empty)
    empty.location = (1.0, 2.0, 3.0)
    bpy.context.view_layer.update()
    assert reader.probe_center(scene).tolist() == [1.0, 2.0, 3.0]
    scene["probe_center"] = (4.0, 5.0, 6.0)
    assert reader.probe_center(scene).tolist() == [4.0, 5.0, 6.0]
    scene.dimred.probe_center = (7.0, 8.0, 9.0)  # not switched on: ignored
    assert reader.probe_center(scene).tolist() == [4.0, 5.0, 6.0]
    scene.dimred.use_probe_center = True
    notes: list[str] = []
    assert reader.probe_center(scene, notes=notes).tolist() == [7.0, 8.0, 9.0]
    assert notes == ["probe centre (7, 8, 9) from scene.dimred.probe_center"]
    data = reader.read_scene(scene, center=(0.5, -0.5, 1.5))
    assert data.center.tolist() == [0.5, -0.5, 1.5]
    assert "probe centre (0.5, -0.5, 1.5) as given" in data.notes


def test_probe_centre_of_a_parented_empty_is_its_world_location(world):
    parent = bpy.data.objects.new("Rig", None)
    child = bpy.data.objects.new("ProbeCenter", None)
    for obj in (parent, child):
        bpy.context.scene.collection.objects.link(obj)
    child.parent = parent
    parent.location = (1.0, 0.0, 0.0)
    child.location = (0.0, 0.0, 1.5)
    bpy.context.view_layer.update()
    notes: list[str] = []
    assert reader.probe_center(bpy.context.scene, notes=notes).tolist() == [1.0, 0.0, 1.5]
    assert notes == ["probe centre (1, 0, 1.5) from object 'ProbeCenter'"]


def test_saved_setting_is_read_without_the_add_on(world, settings_registered, tmp_path):
    """The command line opens a .blend saved with the add-on without registering it."""
    scene = bpy.context.scene
    scene.dimred.probe_center = (0.25, 0.5, 1.25)
    scene.dimred.use_probe_center = True
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "saved.blend"))
    del bpy.types.Scene.dimred
    bpy.utils.unregister_class(_Settings)
    try:
        bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "saved.blend"), load_ui=False)
        assert reader.probe_center(bpy.context.scene).tolist() == [0.25, 0.5, 1.25]
    finally:
        bpy.utils.register_class(_Settings)
        bpy.types.Scene.dimred = bpy.props.PointerProperty(type=_Settings)


@pytest.mark.parametrize("bad", [(1.0, 2.0), ("a", 0, 0), (0.0, float("nan"), 0.0)])
def test_bad_probe_centre(world, bad):
    with pytest.raises(DimredError, match="three"):
        reader.read_scene(bpy.context.scene, center=bad)


# --- errors ---------------------------------------------------------------------------------


def _error(scene=None) -> str:
    with pytest.raises(DimredError) as caught:
        reader.read_scene(scene or bpy.context.scene)
    assert "\n" not in str(caught.value)
    return str(caught.value)


def test_error_no_world():
    assert _error() == "scene 'Scene' has no world: add a World with an Environment Texture holding the HDR panorama"


@pytest.mark.skipif(bpy.app.version >= (5, 0, 0), reason="worlds always have node trees from Blender 5.0 on")
def test_error_world_without_nodes():
    world = bpy.data.worlds.new("Plain")
    world.use_nodes = False
    bpy.context.scene.world = world
    assert "does not use nodes" in _error()


def test_error_no_world_output(world):
    world.nodes.remove(world.nodes["World Output"])
    assert _error() == "world 'Probe' has no active World Output node"


def test_error_no_environment_texture(world):
    world.nodes.remove(world.nodes["Environment Texture"])
    assert "world 'Probe' shows no Environment Texture" in _error()


def test_error_environment_texture_without_image(world):
    world.nodes["Environment Texture"].image = None
    assert _error() == "Environment Texture 'Environment Texture' in world 'Probe' has no image"


def test_error_image_file_missing(panorama_world, tmp_path):
    image = bpy.data.images.new("lost", 4, 2, float_buffer=True)
    image.source = 'FILE'
    image.filepath = str(tmp_path / "lost.exr")
    panorama_world(image)
    assert _error() == f"cannot load image 'lost': file not found: {tmp_path / 'lost.exr'}"


@pytest.mark.parametrize("name", ["broken.exr", "broken.hdr"])
def test_error_image_unreadable(panorama_world, tmp_path, name):
    (tmp_path / name).write_bytes(b"definitely not an image" * 10)
    image = bpy.data.images.new("broken", 4, 2, float_buffer=True)
    image.source = 'FILE'
    image.filepath = str(tmp_path / name)
    panorama_world(image)
    message = _error()
    assert str(tmp_path / name) in message
    assert "not an OpenEXR file" in message or "Blender cannot read the file" in message


def test_error_texture_through_a_colour_changing_node(world):
    nodes, links = world.nodes, world.links
    hue = nodes.new("ShaderNodeHueSaturation")
    links.new(nodes["Environment Texture"].outputs["Color"], hue.inputs["Color"])
    links.new(hue.outputs["Color"], nodes["Background"].inputs["Color"])
    assert "passes through node 'Hue/Saturation/Value'" in _error()


def test_muted_nodes_pass_their_input_through(panorama_world, panorama_file):
    tree = panorama_world(bpy.data.images.load(str(panorama_file[0])), ("POINT", (0.0, 0.0, 1.0), (1.0, 1.0, 1.0)))
    nodes, links = tree.nodes, tree.links
    hue = nodes.new("ShaderNodeHueSaturation")
    links.new(nodes["Environment Texture"].outputs["Color"], hue.inputs["Color"])
    links.new(hue.outputs["Color"], nodes["Background"].inputs["Color"])
    hue.mute = True
    nodes["Mapping"].mute = True
    data = reader.read_scene(bpy.context.scene)
    np.testing.assert_array_equal(data.hdri, panorama_file[1])
    np.testing.assert_array_equal(data.rotation, np.eye(3))


def test_error_mirror_ball_projection(world):
    world.nodes["Environment Texture"].projection = 'MIRROR_BALL'
    assert "only equirectangular panoramas are supported" in _error()


def test_error_non_uniform_mapping_scale(panorama_world, panorama_file):
    panorama_world(bpy.data.images.load(str(panorama_file[0])), ("POINT", (0.0, 0.0, 0.0), (1.0, 2.0, 1.0)))
    assert "Mapping node 'Mapping' scales by (1, 2, 1)" in _error()


def test_error_mapping_without_vector(panorama_world, panorama_file):
    tree = panorama_world(bpy.data.images.load(str(panorama_file[0])), ("POINT", (0.0, 0.0, 0.5), (1.0, 1.0, 1.0)))
    tree.links.remove(tree.nodes["Mapping"].inputs["Vector"].links[0])
    assert "has nothing connected to its Vector input" in _error()


def test_check_object(world):
    scene = bpy.context.scene
    _cube("Box")
    _cube("Ghost").hide_render = True
    scene.collection.objects.link(bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera")))
    reader.check_object(scene, "Box")
    with pytest.raises(DimredError, match=r"^no object named 'Chair' in scene 'Scene'$"):
        reader.check_object(scene, "Chair")
    with pytest.raises(DimredError, match=r"^'Camera' is a CAMERA, not a mesh: only mesh objects can be removed$"):
        reader.check_object(scene, "Camera")
    with pytest.raises(DimredError, match="'Ghost' is hidden for render"):
        reader.check_object(scene, "Ghost")
