"""The world shader layer that shows HDRI + difference, and the difference image it reads.

The original nodes stay as they are: a second Environment Texture (the difference image) is fed
by the same vector as the original one, and a Mix node (RGBA, Add, factor 1) between the
original texture and the Background adds it. Both new nodes sit in a frame labelled
"Diminished Reality". Adding the layer again replaces it; removing it relinks the original.

While a run computes, a preview sits between whatever the Background got before and the
Background: two more Environment Textures (the preview's colour and mask, both small) and two
Mix nodes that show before * (1 - mask) + colour (`addon.run.preview`), in a frame of their
own. Removing the preview relinks what it sat on, so a cancelled run leaves the world as it was.
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
PREVIEW_TEXTURE_NAME = "DimRed Preview"
PREVIEW_MASK_NAME = "DimRed Preview Mask"
PREVIEW_KEEP_NAME = "DimRed Preview Keep"  # before * (1 - mask)
PREVIEW_ADD_NAME = "DimRed Preview Add"
PREVIEW_FRAME_NAME = "DimRed Preview Frame"
PREVIEW_NODE_NAMES = (PREVIEW_TEXTURE_NAME, PREVIEW_MASK_NAME, PREVIEW_KEEP_NAME, PREVIEW_ADD_NAME, PREVIEW_FRAME_NAME)

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
    # Through the preview and the layer, each of which passes on its Mix node's A input.
    for name in (PREVIEW_ADD_NAME, PREVIEW_KEEP_NAME, MIX_NAME):
        if source is not None and source.name == name:
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
    """Remove our nodes (a preview's too) and link the original texture to the Background again.

    Returns the difference image the layer showed (the caller decides whether to delete it).
    """
    remove_preview(world)
    if not has_layer(world):
        return None
    image = layer_image(world)
    _remove_nodes(world.node_tree, (MIX_NAME,), LAYER_NODE_NAMES)
    return image


def _remove_nodes(tree: bpy.types.NodeTree, mixes: tuple[str, ...], names: tuple[str, ...]) -> None:
    """Remove the nodes `names`, first linking what reaches the chain of Mix nodes `mixes`
    (each fed by the next one's result through its A input, the first's feeding the rest of
    the tree) to where the first one's result went."""
    first = tree.nodes.get(mixes[0])
    last = tree.nodes.get(mixes[-1])
    if first is not None and last is not None:
        a_input = _socket(last.inputs, "A_Color")
        source = a_input.links[0].from_socket if a_input.is_linked else None
        targets = [link.to_socket for link in _socket(first.outputs, "Result_Color").links]
        if source is not None:
            for target in targets:
                tree.links.new(source, target)
    for name in names:
        node = tree.nodes.get(name)
        if node is not None:
            tree.nodes.remove(node)


def add_layer(world: bpy.types.World, image: bpy.types.Image) -> None:
    """Show HDRI + `image` in the world, replacing a layer (and a preview) added before."""
    environment, background = world_nodes(world)
    remove_layer(world)
    texture = _texture(world.node_tree, environment, TEXTURE_NAME, image)
    mix = _mix(world.node_tree, MIX_NAME, 'ADD')
    links = world.node_tree.links
    links.new(environment.outputs["Color"], _socket(mix.inputs, "A_Color"))
    links.new(texture.outputs["Color"], _socket(mix.inputs, "B_Color"))
    links.new(_socket(mix.outputs, "Result_Color"), background.inputs["Color"])
    x, y = environment.location
    texture.location = (x, y - 320.0)
    mix.location = ((x + background.location.x) / 2.0, y - 160.0)
    _frame(world.node_tree, FRAME_NAME, FRAME_LABEL, (texture, mix))


def preview_image(world: bpy.types.World) -> bpy.types.Image | None:
    """The colour image of the preview the world shows, if any."""
    node = world.node_tree.nodes.get(PREVIEW_TEXTURE_NAME) if world.node_tree is not None else None
    return node.image if node is not None else None


def show_preview(world: bpy.types.World, color: bpy.types.Image, mask: bpy.types.Image) -> None:
    """Show what the world shows now * (1 - `mask`) + `color`, or, with a preview shown
    already, show these images in it."""
    nodes = world.node_tree.nodes
    if nodes.get(PREVIEW_TEXTURE_NAME) is None:
        _add_preview(world)
    nodes[PREVIEW_TEXTURE_NAME].image = color
    nodes[PREVIEW_MASK_NAME].image = mask


def remove_preview(world: bpy.types.World) -> None:
    """Remove the preview's nodes and link what it sat on to the Background again."""
    if world.node_tree is not None:
        _remove_nodes(world.node_tree, (PREVIEW_ADD_NAME, PREVIEW_KEEP_NAME), PREVIEW_NODE_NAMES)


def _add_preview(world: bpy.types.World) -> None:
    environment, background = world_nodes(world)
    tree = world.node_tree
    shown = background.inputs["Color"].links[0].from_socket
    color = _texture(tree, environment, PREVIEW_TEXTURE_NAME, None)
    mask = _texture(tree, environment, PREVIEW_MASK_NAME, None)
    keep = _mix(tree, PREVIEW_KEEP_NAME, 'MIX')
    _socket(keep.inputs, "B_Color").default_value = (0.0, 0.0, 0.0, 1.0)
    add = _mix(tree, PREVIEW_ADD_NAME, 'ADD')
    links = tree.links
    links.new(mask.outputs["Color"], _socket(keep.inputs, "Factor_Float"))
    links.new(shown, _socket(keep.inputs, "A_Color"))
    links.new(_socket(keep.outputs, "Result_Color"), _socket(add.inputs, "A_Color"))
    links.new(color.outputs["Color"], _socket(add.inputs, "B_Color"))
    links.new(_socket(add.outputs, "Result_Color"), background.inputs["Color"])
    x, y = background.location
    color.location, mask.location = (x - 700.0, y + 560.0), (x - 700.0, y + 300.0)
    keep.location, add.location = (x - 420.0, y + 400.0), (x - 200.0, y + 300.0)
    _frame(tree, PREVIEW_FRAME_NAME, f"{FRAME_LABEL} preview", (color, mask, keep, add))


def _texture(tree: bpy.types.NodeTree, environment: bpy.types.Node, name: str,
             image: bpy.types.Image | None) -> bpy.types.Node:
    """An Environment Texture that samples `image` as the original `environment` samples its own."""
    texture = tree.nodes.new("ShaderNodeTexEnvironment")
    texture.name = texture.label = name
    texture.image = image
    texture.projection = environment.projection
    texture.interpolation = environment.interpolation
    vector = environment.inputs["Vector"]
    if vector.is_linked:
        tree.links.new(vector.links[0].from_socket, texture.inputs["Vector"])
    return texture


def _mix(tree: bpy.types.NodeTree, name: str, blend: str) -> bpy.types.Node:
    mix = tree.nodes.new("ShaderNodeMix")
    mix.name = mix.label = name
    mix.data_type = 'RGBA'
    mix.blend_type = blend
    # Radiance is unbounded: clamping the result to [0, 1] would flatten the HDRI.
    mix.clamp_result = False
    _socket(mix.inputs, "Factor_Float").default_value = 1.0
    return mix


def _frame(tree: bpy.types.NodeTree, name: str, label: str, members: tuple[bpy.types.Node, ...]) -> None:
    frame = tree.nodes.new("NodeFrame")
    frame.name = name
    frame.label = label
    for node in members:
        node.parent = frame


def load_difference_image(filepath: str, name: str) -> bpy.types.Image:
    """Load (or reload) the difference EXR as the image `name`, with no colour conversion."""
    image = bpy.data.images.get(name)
    if image is None:
        image = bpy.data.images.load(filepath)
        image.name = name
    else:
        if image.packed_file is not None:
            image.unpack(method='REMOVE')  # the packed pixels are the old file's: reload would keep them
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
