"""The removal operators end to end on the tiny room: remove, run again, save the HDRI, clear;
and a refused run that changes nothing."""
from __future__ import annotations

import json
from pathlib import Path

import bpy
import numpy as np
import pytest

import tiny_scene


@pytest.fixture
def room(registered, tmp_path) -> Path:
    """The tiny room saved as a .blend in tmp_path, with the box marked for removal."""
    hdri = tmp_path / "room.exr"
    tiny_scene.write_exr(hdri, tiny_scene.synthetic_hdri(64, 32))
    tiny_scene.build_scene(hdri)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "room.blend"))
    settings = bpy.context.scene.dimred
    settings.target = bpy.data.objects["Box"]
    settings.quality = "draft"
    return hdri


def test_remove_save_and_clear(room, tmp_path, extension):
    from diminished_reality.operators import world_layer

    world = bpy.context.scene.world
    links_before = {(l.from_node.name, l.to_node.name) for l in world.node_tree.links}

    assert bpy.ops.dimred.remove() == {'FINISHED'}
    difference_file = tmp_path / "dimred" / "Room_Probe_difference.exr"
    assert difference_file.is_file()
    assert world_layer.has_layer(world)
    assert json.loads(bpy.context.scene.dimred.last_report)["seconds"]["total"] > 0
    assert world_layer.layer_image(world).filepath == "//dimred/Room_Probe_difference.exr"
    difference = tiny_scene.read_exr(difference_file)
    np.testing.assert_array_equal(world_layer.image_rgb(world_layer.layer_image(world)), difference)

    assert bpy.ops.dimred.remove() == {'FINISHED'}
    assert sum(n.type == 'TEX_ENVIRONMENT' for n in world.node_tree.nodes) == 2

    edited_file = tmp_path / "edited.exr"
    assert bpy.ops.dimred.save_hdri(filepath=str(edited_file)) == {'FINISHED'}
    np.testing.assert_allclose(
        tiny_scene.read_exr(edited_file), tiny_scene.read_exr(room) + difference, rtol=1e-6, atol=1e-6
    )

    image_name = world_layer.layer_image(world).name
    assert bpy.ops.dimred.clear() == {'FINISHED'}
    assert {(l.from_node.name, l.to_node.name) for l in world.node_tree.links} == links_before
    assert image_name not in bpy.data.images


def test_refused_removal_changes_nothing(room, tmp_path):
    bpy.data.objects["Box"].hide_render = True

    with pytest.raises(RuntimeError, match="hidden for render"):
        bpy.ops.dimred.remove()

    assert not (tmp_path / "dimred").exists()
    assert bpy.context.scene.dimred.last_report == ""
    assert len(bpy.context.scene.world.node_tree.nodes) == 3
