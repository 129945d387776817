"""The world shader layer: HDRI + difference through a Mix (Add) node, replaced not stacked,
removed without a trace; and the difference image loaded without colour conversion."""
from __future__ import annotations

import bpy
import numpy as np
import pytest

from tests.blender.tiny_scene import environment_world, write_exr


@pytest.fixture
def world_layer(extension):
    from diminished_reality.operators.support import world_layer

    return world_layer


def _world(with_mapping: bool) -> bpy.types.World:
    world, environment = environment_world(bpy, "Probe", bpy.data.images.new("hdri", 8, 4, float_buffer=True))
    nodes, links = world.node_tree.nodes, world.node_tree.links
    if with_mapping:
        coordinates = nodes.new("ShaderNodeTexCoord")
        mapping = nodes.new("ShaderNodeMapping")
        mapping.inputs["Rotation"].default_value[2] = 1.0
        links.new(coordinates.outputs["Generated"], mapping.inputs["Vector"])
        links.new(mapping.outputs["Vector"], environment.inputs["Vector"])
    return world


def _links(world: bpy.types.World) -> set[tuple[str, str, str, str]]:
    return {
        (link.from_node.name, link.from_socket.identifier, link.to_node.name, link.to_socket.identifier)
        for link in world.node_tree.links
    }


def _difference_image() -> bpy.types.Image:
    return bpy.data.images.new("difference", 8, 4, float_buffer=True)


@pytest.mark.parametrize("with_mapping", [False, True], ids=["plain", "mapping"])
def test_layer_adds_difference_before_background(world_layer, with_mapping):
    world = _world(with_mapping)
    environment, background = world_layer.world_nodes(world)
    image = _difference_image()

    world_layer.add_layer(world, image)

    nodes = world.node_tree.nodes
    texture, mix, frame = (nodes[name] for name in world_layer.LAYER_NODE_NAMES)
    assert texture.image == image
    assert (mix.data_type, mix.blend_type, mix.clamp_result) == ('RGBA', 'ADD', False)
    assert next(s for s in mix.inputs if s.identifier == "Factor_Float").default_value == 1.0
    assert texture.parent == frame and mix.parent == frame and frame.label == "Diminished Reality"

    vector_sources = [
        tuple((link.from_node.name, link.from_socket.identifier) for link in node.inputs["Vector"].links)
        for node in (environment, texture)
    ]
    assert vector_sources[0] == vector_sources[1]
    assert bool(vector_sources[0]) == with_mapping

    links = _links(world)
    assert (environment.name, "Color", mix.name, "A_Color") in links
    assert (texture.name, "Color", mix.name, "B_Color") in links
    assert (mix.name, "Result_Color", background.name, "Color") in links
    assert not any(to_node == background.name and to_socket == "Color" and from_node != mix.name
                   for from_node, _, to_node, to_socket in links)
    assert world_layer.world_nodes(world) == (environment, background)


def test_adding_again_replaces_the_layer(world_layer):
    world = _world(with_mapping=True)
    world_layer.add_layer(world, _difference_image())
    nodes_once, links_once = len(world.node_tree.nodes), _links(world)
    second = _difference_image()

    world_layer.add_layer(world, second)

    assert len(world.node_tree.nodes) == nodes_once
    assert _links(world) == links_once
    assert sum(n.type == 'TEX_ENVIRONMENT' for n in world.node_tree.nodes) == 2
    assert world_layer.layer_image(world) == second


@pytest.mark.parametrize("with_mapping", [False, True], ids=["plain", "mapping"])
def test_clear_restores_the_original_exactly(world_layer, with_mapping):
    world = _world(with_mapping)
    nodes_before = sorted(n.name for n in world.node_tree.nodes)
    links_before = _links(world)
    image = _difference_image()
    world_layer.add_layer(world, image)

    assert world_layer.remove_layer(world) == image

    assert sorted(n.name for n in world.node_tree.nodes) == nodes_before
    assert _links(world) == links_before
    assert not world_layer.has_layer(world)
    assert world_layer.remove_layer(world) is None


def test_world_without_environment_texture_is_refused(world_layer, extension):
    world = bpy.data.worlds.new("Plain")
    if world.node_tree is None:
        world.use_nodes = True
    nodes_before = len(world.node_tree.nodes)
    with pytest.raises(extension.addon.errors.DimredError, match="Environment Texture"):
        world_layer.add_layer(world, _difference_image())
    assert len(world.node_tree.nodes) == nodes_before


def test_difference_image_loads_raw_and_top_row_first(world_layer, tmp_path):
    rows = np.linspace(-2.0, 40.0, 4, dtype=np.float32)  # negative and > 1: no clamping, no transform
    pixels = np.broadcast_to(rows[:, None, None], (4, 8, 3)) * np.array([1.0, 0.5, 0.25], np.float32)
    path = tmp_path / "difference.exr"
    write_exr(path, pixels)

    image = world_layer.load_difference_image(str(path), "test difference")

    assert image.colorspace_settings.name == world_layer.DIFFERENCE_COLORSPACE
    np.testing.assert_allclose(world_layer.image_rgb(image), pixels, rtol=1e-6)

    write_exr(path, pixels * 2.0)
    reloaded = world_layer.load_difference_image(str(path), "test difference")
    assert reloaded == image
    np.testing.assert_allclose(world_layer.image_rgb(reloaded), pixels * 2.0, rtol=1e-6)


def _flat(pixels: np.ndarray) -> np.ndarray:
    """(H, W, 3) top row first -> an Image.pixels buffer."""
    rgba = np.ones((*pixels.shape[:2], 4), np.float32)
    rgba[..., :3] = pixels[::-1]
    return rgba.ravel()


def _image(name: str, pixels: np.ndarray) -> bpy.types.Image:
    image = bpy.data.images.new(name, pixels.shape[1], pixels.shape[0], alpha=True, float_buffer=True)
    image.colorspace_settings.name = 'Non-Color'
    image.pixels.foreach_set(_flat(pixels))
    return image


@pytest.mark.parametrize("layered", [False, True], ids=["original", "over a layer"])
@pytest.mark.parametrize("with_mapping", [False, True], ids=["plain", "mapping"])
def test_a_preview_sits_over_what_the_world_shows_and_leaves_no_trace(world_layer, extension, layered, with_mapping):
    from addon.blender import reader

    world = _world(with_mapping)
    if layered:
        world_layer.add_layer(world, _difference_image())
    nodes_before, links_before = sorted(n.name for n in world.node_tree.nodes), _links(world)
    environment, background = world_layer.world_nodes(world)
    color, mask = _difference_image(), _difference_image()

    world_layer.show_preview(world, color, mask)
    world_layer.show_preview(world, color, mask)

    nodes = world.node_tree.nodes
    keep, add = nodes[world_layer.PREVIEW_KEEP_NAME], nodes[world_layer.PREVIEW_ADD_NAME]
    assert world_layer.preview_image(world) == color and nodes[world_layer.PREVIEW_MASK_NAME].image == mask
    assert (keep.blend_type, add.blend_type, keep.clamp_result, add.clamp_result) == ('MIX', 'ADD', False, False)
    assert (add.name, "Result_Color", background.name, "Color") in _links(world)
    assert len(nodes) == len(nodes_before) + len(world_layer.PREVIEW_NODE_NAMES)
    assert world_layer.world_nodes(world) == (environment, background)
    assert world_layer.has_layer(world) == layered
    # The reader sees through it: a file saved during a run still reads as the panorama.
    bpy.context.scene.world = world
    assert reader.read_scene(bpy.context.scene).hdri.shape == (4, 8, 3)

    world_layer.remove_preview(world)
    assert sorted(n.name for n in world.node_tree.nodes) == nodes_before and _links(world) == links_before
    world_layer.show_preview(world, color, mask)
    world_layer.add_layer(world, _difference_image())
    assert world_layer.preview_image(world) is None and world_layer.has_layer(world)


@pytest.mark.slow
@pytest.mark.parametrize("layered", [False, True], ids=["original", "over a layer"])
def test_cycles_renders_the_preview_over_the_world(world_layer, panorama_world, render_world, layered):
    rng = np.random.default_rng(3)
    hdri = rng.random((32, 64, 3)).astype(np.float32)
    difference = rng.normal(0.0, 0.2, (32, 64, 3)).astype(np.float32)
    color = rng.normal(0.0, 1.0, (32, 64, 3)).astype(np.float32)
    mask = rng.choice(np.array([0.0, 0.25, 1.0], np.float32), (32, 64))
    panorama_world(_image("hdri", hdri))
    world = bpy.context.scene.world
    shown = hdri
    if layered:
        world_layer.add_layer(world, _image("difference", difference))
        shown = hdri + difference
    world_layer.show_preview(world, _image("preview", color), _image("mask", np.repeat(mask[..., None], 3, 2)))
    render = render_world(64, 32)
    np.testing.assert_allclose(render, shown * (1.0 - mask[..., None]) + color, atol=1e-5)
