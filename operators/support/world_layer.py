"""The world shader layer that shows HDRI + difference, and the difference image it reads.

The original nodes stay as they are: a second Environment Texture (the difference image) is fed
by the same vector as the original one, and a Mix node (RGBA, Add, factor 1) between the
original texture and the Background adds it. Both new nodes sit in a frame labelled
"Diminished Reality". Adding the layer again replaces it; removing it relinks the original.
"""
from __future__ import annotations

import bpy
import numpy as np

from ...addon.errors import DimredError

TEXTURE_NAME = "DimRed Difference"
MIX_NAME = "DimRed Add"
FRAME_NAME = "DimRed Frame"
FRAME_LABEL = "Diminished Reality"
LAYER_NODE_NAMES = (TEXTURE_NAME, MIX_NAME, FRAME_NAME)

# The difference holds raw scene-linear values computed from the HDRI's pixels, so Blender must
# not convert it: 'Non-Color' is a no-op in every working space ('Linear Rec.709' would be
# converted when the .blend uses another working space, which Blender 5 allows).
DIFFERENCE_COLORSPACE = 'Non-Color'


def _socket(sockets: bpy.types.NodeInputs | bpy.types.NodeOutputs, identifier: str) -> bpy.types.NodeSocket:
    # The Mix node has A/B/Result sockets for every data type, all with the same names.
    return next(s for s in sockets if s.identifier == identifier)


def _linked_node(socket: bpy.types.NodeSocket) -> bpy.types.Node | None:
    return socket.links[0].from_node if socket.is_linked else None


def world_nodes(world: bpy.types.World) -> tuple[bpy.types.Node, bpy.types.Node]:
    """The world's original (Environment Texture, Background) pair, whether or not our layer is in.

    Raises DimredError when the world is not lit by an image through a Background node.
    """
    tree = world.node_tree
    outputs = [n for n in tree.nodes if n.type == 'OUTPUT_WORLD'] if tree is not None else []
    if not outputs:
        raise DimredError(f"World '{world.name}' has no World Output node; light it with an HDRI first")
    output = next((n for n in outputs if n.is_active_output), outputs[0])
    background = _linked_node(output.inputs["Surface"])
    if background is None or background.type != 'BACKGROUND':
        raise DimredError(f"World '{world.name}': the World Output's Surface must come from a Background node")
    source = _linked_node(background.inputs["Color"])
    if source is not None and source.name == MIX_NAME:
        source = _linked_node(_socket(source.inputs, "A_Color"))
    if source is None or source.type != 'TEX_ENVIRONMENT' or source.image is None:
        raise DimredError(
            f"World '{world.name}': the Background's Color must come straight from an "
            "Environment Texture with the panorama image"
        )
    return source, background


def has_layer(world: bpy.types.World | None) -> bool:
    """Whether the world shows a difference layer of ours."""
    tree = world.node_tree if world is not None else None
    return tree is not None and any(tree.nodes.get(name) is not None for name in LAYER_NODE_NAMES)


def layer_image(world: bpy.types.World) -> bpy.types.Image | None:
    """The difference image the world's layer shows, if any."""
    node = world.node_tree.nodes.get(TEXTURE_NAME) if world.node_tree is not None else None
    return node.image if node is not None else None


def remove_layer(world: bpy.types.World) -> bpy.types.Image | None:
    """Remove our nodes and link the original texture to the Background again.

    Returns the difference image the layer showed (the caller decides whether to delete it).
    """
    if not has_layer(world):
        return None
    tree = world.node_tree
    image = layer_image(world)
    mix = tree.nodes.get(MIX_NAME)
    if mix is not None:
        a_input = _socket(mix.inputs, "A_Color")
        source = a_input.links[0].from_socket if a_input.is_linked else None
        targets = [link.to_socket for link in _socket(mix.outputs, "Result_Color").links]
        if source is not None:
            for target in targets:
                tree.links.new(source, target)
    for name in LAYER_NODE_NAMES:
        node = tree.nodes.get(name)
        if node is not None:
            tree.nodes.remove(node)
    return image


def add_layer(world: bpy.types.World, image: bpy.types.Image) -> None:
    """Show HDRI + `image` in the world, replacing a layer added before."""
    environment, background = world_nodes(world)
    remove_layer(world)
    tree = world.node_tree
    nodes, links = tree.nodes, tree.links

    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.name = texture.label = TEXTURE_NAME
    texture.image = image
    texture.projection = environment.projection
    texture.interpolation = environment.interpolation
    vector = environment.inputs["Vector"]
    if vector.is_linked:
        links.new(vector.links[0].from_socket, texture.inputs["Vector"])

    mix = nodes.new("ShaderNodeMix")
    mix.name = mix.label = MIX_NAME
    mix.data_type = 'RGBA'
    mix.blend_type = 'ADD'
    # Radiance is unbounded: clamping the sum to [0, 1] would flatten the HDRI.
    mix.clamp_result = False
    _socket(mix.inputs, "Factor_Float").default_value = 1.0
    links.new(environment.outputs["Color"], _socket(mix.inputs, "A_Color"))
    links.new(texture.outputs["Color"], _socket(mix.inputs, "B_Color"))
    links.new(_socket(mix.outputs, "Result_Color"), background.inputs["Color"])

    x, y = environment.location
    texture.location = (x, y - 320.0)
    mix.location = ((x + background.location.x) / 2.0, y - 160.0)
    frame = nodes.new("NodeFrame")
    frame.name = FRAME_NAME
    frame.label = FRAME_LABEL
    texture.parent = frame
    mix.parent = frame


def load_difference_image(filepath: str, name: str) -> bpy.types.Image:
    """Load (or reload) the difference EXR as the image `name`, with no colour conversion."""
    image = bpy.data.images.get(name)
    if image is None:
        image = bpy.data.images.load(filepath)
        image.name = name
    else:
        image.filepath = filepath
    image.colorspace_settings.name = DIFFERENCE_COLORSPACE
    # The file may have been rewritten under the same path: drop any cached pixels.
    image.reload()
    return image


def image_rgb(image: bpy.types.Image) -> np.ndarray:
    """(H, W, 3) float32 pixels of a Blender image, row 0 at the top (as in an EXR file)."""
    width, height = image.size
    if width == 0 or height == 0:
        raise DimredError(f"Image '{image.name}' has no pixels (is its file '{image.filepath}' missing?)")
    pixels = np.empty(width * height * image.channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    # Blender stores the bottom row first.
    return np.ascontiguousarray(pixels.reshape(height, width, image.channels)[::-1, :, :3])
