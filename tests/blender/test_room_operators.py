"""Match Room through bpy as a user works: clicks added with `dimred.room_click`, the room built
by `dimred.match_room`, read back from the meshes; a moved click re-fits; bad clicks change
nothing."""
from __future__ import annotations

import json
from pathlib import Path

import bpy
import numpy as np
import pytest

from tests.blender import tiny_scene
from tests.engine.roommatch.room_truth import clicks_of, distance_errors, flat_panorama, floor_points

W, H = 512, 256
BOX = np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)])
PROBE = np.array([0.0, 0.0, 1.5])
CEILING = 2.6


@pytest.fixture
def panorama_room(registered, tmp_path: Path) -> np.ndarray:
    """An empty scene whose world shows a flat panorama of the box room; returns the floor clicks."""
    from addon.blender import room_builder

    hdri = tmp_path / "room.exr"
    tiny_scene.write_exr(hdri, flat_panorama(BOX, CEILING, PROBE, W, H))
    room_builder.show_panorama(bpy.context.scene, str(hdri))
    return clicks_of(floor_points(BOX), PROBE, W, H)


def _vertices(name: str) -> np.ndarray:
    mesh = bpy.data.objects[name].data
    out = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", out)
    return out.reshape(-1, 3)


def _click_all(points: np.ndarray) -> None:
    for x, y in points:
        bpy.ops.dimred.room_click(kind='FLOOR', x=float(x), y=float(y))


def _show_chair(folder: Path, chair: np.ndarray) -> None:
    """Make the world show the box room at 1024 x 512 with an olive box (`silhouette`'s parameters) in it."""
    from addon.blender import room_builder
    from tests.engine.roommatch.room_truth import with_box

    hdri = folder / "chair.exr"
    tiny_scene.write_exr(hdri, with_box(flat_panorama(BOX, CEILING, PROBE, 1024, 512), chair, 1.5, (0.7, 0.6, 0.1)))
    room_builder.show_panorama(bpy.context.scene, str(hdri))


def _chair_in_matched_room(folder: Path) -> np.ndarray:
    """The box room with an armchair-sized box, matched from its corners' clicks; the box's parameters."""
    chair = np.array([1.8, 0.6, np.log(0.8), np.log(0.7), np.log(0.9), np.radians(20.0)])
    _show_chair(folder, chair)
    _click_all(clicks_of(floor_points(BOX), PROBE, 1024, 512))
    bpy.context.scene.dimred_room.camera_height = 1.5
    bpy.ops.dimred.match_room()
    return chair


def test_match_room_builds_the_room_the_clicks_show(panorama_room: np.ndarray) -> None:
    scene = bpy.context.scene
    _click_all(panorama_room)
    ceiling = clicks_of(np.array([[3.0, 0.5, CEILING]]), PROBE, W, H)[0]
    bpy.ops.dimred.room_click(kind='CEILING', x=float(ceiling[0]), y=float(ceiling[1]))
    scene.dimred_room.camera_height = 1.5
    assert bpy.ops.dimred.match_room() == {'FINISHED'}

    floor = _vertices("Floor")
    assert np.allclose(floor[:, 2], 0.0)
    found = floor[[int(np.argmin(np.linalg.norm(floor[:, :2] - c, axis=1))) for c in BOX], :2]
    assert distance_errors(found, BOX, PROBE).max() < 0.02  # 512 wide: a whole pixel is 0.7 degrees
    assert len(bpy.data.objects["Walls"].data.polygons) == 4
    assert _vertices("Ceiling")[:, 2] == pytest.approx(CEILING, rel=0.03)
    assert tuple(scene.objects["ProbeCenter"].location) == pytest.approx((0.0, 0.0, 1.5))
    assert tuple(scene.dimred.probe_center) == pytest.approx((0.0, 0.0, 1.5)) and scene.dimred.use_probe_center
    picture = bpy.data.images["Dimred Room Diagnostics"]
    assert tuple(picture.size) == (W, H)
    assert json.loads(scene.dimred_room.summary)["camera_height_m"] == 1.5


def test_moving_a_click_refits_the_room(panorama_room: np.ndarray) -> None:
    scene = bpy.context.scene
    _click_all(panorama_room)
    scene.dimred_room.camera_height = 1.5
    bpy.ops.dimred.match_room()
    moved = clicks_of(np.array([[-2.5, -1.5, 0.0]]), PROBE, W, H, rounded=False)[0]
    scene.dimred_room.corners[0].point = tuple(moved)  # a user dragging corner 0 half a metre along the wall
    floor = _vertices("Floor")
    assert np.min(np.linalg.norm(floor[:, :2] - (-2.5, -1.5), axis=1)) < 0.02
    back = clicks_of(np.array([[-2.0, -1.5, 0.0]]), PROBE, W, H, rounded=False)[0]
    assert bpy.ops.dimred.room_click(kind='MOVE', x=float(back[0]), y=float(back[1])) == {'FINISHED'}  # Alt+click
    assert np.min(np.linalg.norm(_vertices("Floor")[:, :2] - (-2.0, -1.5), axis=1)) < 0.02
    scene.dimred_room.camera_height = 2.0  # and a new height scales the room about the probe at once
    assert np.min(np.linalg.norm(_vertices("Floor")[:, :2] - (-2.0 * 4 / 3, -1.5 * 4 / 3), axis=1)) < 0.03
    assert json.loads(scene.dimred_room.summary)["camera_height_m"] == 2.0


def test_bad_clicks_change_nothing(panorama_room: np.ndarray) -> None:
    scene = bpy.context.scene
    _click_all(panorama_room[:2])
    with pytest.raises(RuntimeError, match="a floor needs 3 or more corners, 2 clicked"):
        bpy.ops.dimred.match_room()
    assert "Floor" not in bpy.data.objects and "ProbeCenter" not in bpy.data.objects

    _click_all(panorama_room[2:])
    bpy.ops.dimred.match_room()
    before = _vertices("Floor")
    scene.dimred_room.corners[1].point = (panorama_room[1][0], 60.0)  # above the horizon: refused, shown
    assert "floor corner 1" in scene.dimred_room.problem
    assert np.array_equal(_vertices("Floor"), before)
    scene.dimred_room.corners[1].point = tuple(panorama_room[1])
    scene.dimred_room.camera_height = 0.0
    with pytest.raises(RuntimeError, match="camera height must be above 0 m"):
        bpy.ops.dimred.match_room()
    assert np.array_equal(_vertices("Floor"), before)
    with pytest.raises(RuntimeError, match="outside the 512 × 256 panorama"):
        bpy.ops.dimred.room_click(kind='FLOOR', x=600.0, y=200.0)
        scene.dimred_room.camera_height = 1.5
        bpy.ops.dimred.match_room()
    assert np.array_equal(_vertices("Floor"), before)


def test_click_files_load_and_save(panorama_room: np.ndarray, tmp_path: Path) -> None:
    _click_all(panorama_room)
    bpy.ops.dimred.room_save_clicks(filepath=str(tmp_path / "clicks.json"))
    saved = json.loads((tmp_path / "clicks.json").read_text())
    assert saved["floor"] == panorama_room.tolist() and saved["width"] == W
    bpy.ops.dimred.room_clear()
    assert len(bpy.context.scene.dimred_room.corners) == 0
    bpy.ops.dimred.room_load_clicks(filepath=str(tmp_path / "clicks.json"))
    assert [tuple(c.point) for c in bpy.context.scene.dimred_room.corners] == [tuple(p) for p in panorama_room]


def test_snap_to_photo_moves_the_clicks_onto_the_walls(panorama_room: np.ndarray) -> None:
    scene = bpy.context.scene
    _click_all(panorama_room + np.array([[1, -1], [-1, 1], [1, 1], [-1, -1]]))  # each a pixel or two off
    scene.dimred_room.camera_height = 1.5
    bpy.ops.dimred.match_room()
    before = _vertices("Floor")[:, :2]
    assert bpy.ops.dimred.match_room(snap=True) == {'FINISHED'}
    after = _vertices("Floor")[:, :2]

    def error(found: np.ndarray) -> float:
        return float(max(np.min(np.linalg.norm(found - c, axis=1)) for c in BOX))

    assert error(after) < 0.5 * error(before)
    assert [tuple(c.point) for c in scene.dimred_room.corners] != [tuple(p) for p in panorama_room]


def test_object_from_photo_boxes_the_clicked_object(panorama_room: np.ndarray, tmp_path: Path) -> None:
    from addon.roommatch.projection import project

    chair = _chair_in_matched_room(tmp_path)
    x, y = np.round(project(np.array([1.8, 0.6, 0.45 - 1.5]), 1024, 512))
    assert bpy.ops.dimred.object_from_photo(x=float(x), y=float(y), name="Chair") == {'FINISHED'}
    corners = _vertices("Chair")
    assert corners[:, 2].min() == pytest.approx(0.0, abs=1e-6)
    assert corners[:, 2].max() == pytest.approx(0.9, rel=0.08)
    assert corners[:, :2].mean(axis=0) == pytest.approx(chair[:2], abs=0.05)
    assert bpy.context.scene.dimred.target.name == "Chair"


def test_object_from_footprint_builds_a_prism_of_the_fitted_height(panorama_room: np.ndarray, tmp_path: Path) -> None:
    from addon.roommatch.object_box import BoxFit

    chair = _chair_in_matched_room(tmp_path)
    scene = bpy.context.scene
    bottom = BoxFit(np.array([1.8, 0.6, 0.0]), np.array([0.8, 0.7, 0.0]), np.radians(20.0), 0.0, 0).corners()[:4]
    # Where the box meets the floor (an operator's collection argument names each item).
    feet = [{"name": str(i), "point": tuple(p)} for i, p in enumerate(clicks_of(bottom, PROBE, 1024, 512))]
    with pytest.raises(RuntimeError, match="a footprint needs 3 or more contact points, 2 clicked"):
        bpy.ops.dimred.object_footprint(points=feet[:2], name="Chair")
    assert "Chair" not in bpy.data.objects
    assert bpy.ops.dimred.object_footprint(points=feet, name="Chair") == {'FINISHED'}
    corners = _vertices("Chair")
    assert len(corners) == 8 and corners[:, 2].min() == pytest.approx(0.0, abs=1e-6)
    assert corners[:, 2].max() == pytest.approx(0.9, rel=0.05)
    assert corners[:, :2].mean(axis=0) == pytest.approx(chair[:2], abs=0.03)
    assert scene.dimred.target.name == "Chair"


def test_clicks_in_a_view_from_the_probe_land_on_the_panorama(panorama_room: np.ndarray) -> None:
    from mathutils import Vector

    from addon.blender import room_builder
    from tests.engine.roommatch.room_truth import rotation_z

    scene = bpy.context.scene
    tree = scene.world.node_tree  # the world turned 40 degrees by a Mapping node
    mapping = tree.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value[2] = np.radians(40.0)
    tree.links.new(tree.nodes.new("ShaderNodeTexCoord").outputs["Generated"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs["Vector"], tree.nodes["Environment Texture"].inputs["Vector"])
    turned = rotation_z(40.0)
    _click_all(clicks_of(floor_points(BOX), PROBE, W, H, turned))
    scene.dimred_room.camera_height = 1.5
    bpy.ops.dimred.match_room()
    assert bpy.ops.dimred.look_from_probe() == {'FINISHED'}
    camera = scene.camera
    assert camera.name == "Probe Camera" and tuple(camera.location) == pytest.approx(tuple(PROBE))
    assert bpy.data.objects["Walls"].display_type == 'WIRE'  # the world shows through the room
    # The view ray through the middle of the camera's frame, aimed at a corner of the room.
    corner = Vector((3.0, 2.5, 0.0))
    camera.rotation_euler = (corner - camera.location).to_track_quat('-Z', 'Y').to_euler()
    bpy.context.view_layer.update()
    x, y, width, height = room_builder.panorama_pixel(scene, -np.array(camera.matrix_world.col[2][:3]))
    expected = clicks_of(np.array([[3.0, 2.5, 0.0]]), PROBE, W, H, turned, rounded=False)[0]
    assert (width, height) == (W, H) and (x, y) == pytest.approx(tuple(expected), abs=0.01)


def test_suggest_room_proposes_the_corners(panorama_room: np.ndarray, tmp_path: Path) -> None:
    from addon.blender import room_builder

    hdri = tmp_path / "wide.exr"
    tiny_scene.write_exr(hdri, flat_panorama(BOX, CEILING, PROBE, 1024, 512))
    room_builder.show_panorama(bpy.context.scene, str(hdri))
    scene = bpy.context.scene
    scene.dimred_room.camera_height = 1.5
    assert bpy.ops.dimred.room_suggest() == {'FINISHED'}
    assert len(scene.dimred_room.corners) == 4 and scene.dimred_room.manhattan
    assert scene.dimred_room.camera_height == 1.5
    bpy.ops.dimred.match_room()
    floor = _vertices("Floor")[:, :2]
    assert max(np.min(np.linalg.norm(floor - c, axis=1)) for c in BOX) < 0.05


def test_suggest_room_says_when_it_finds_nothing(registered, tmp_path: Path) -> None:
    from addon.blender import room_builder

    hdri = tmp_path / "noise.exr"
    tiny_scene.write_exr(hdri, np.random.default_rng(3).random((128, 256, 3)).astype(np.float32) + 0.1)
    room_builder.show_panorama(bpy.context.scene, str(hdri))
    assert bpy.ops.dimred.room_suggest() == {'CANCELLED'}
    assert len(bpy.context.scene.dimred_room.corners) == 0


def test_fit_box_refits_each_size_of_the_marked_box(panorama_room: np.ndarray, tmp_path: Path) -> None:
    from addon.blender import room_builder
    from addon.roommatch.object_box import BoxFit

    truth = np.array([1.8, 0.6, np.log(0.8), np.log(0.7), np.log(0.95), np.radians(20.0)])
    _show_chair(tmp_path, truth)
    scene = bpy.context.scene
    room_builder.set_probe_center(scene, PROBE)
    # Modelled by eye: 10 cm off, turned 8 degrees too far, 0.8 m high.
    guess = BoxFit(bottom=np.array([1.9, 0.55, 0.0]), size=np.array([0.7, 0.7, 0.8]), turn=np.radians(28.0),
                   agreement=0.0, outline_pixels=0)
    scene.dimred.mark(room_builder.box_object(scene, "Chair", guess.corners()))
    assert bpy.ops.dimred.fit_box() == {'FINISHED'}
    corners = _vertices("Chair")
    assert corners[:, 2].max() == pytest.approx(0.95, rel=0.05)
    assert corners[:, :2].mean(axis=0) == pytest.approx(truth[:2], abs=0.05)
    bpy.data.objects["Chair"].data.vertices[5].co.x += 0.2  # no longer a box
    with pytest.raises(RuntimeError, match="not an upright box"):
        bpy.ops.dimred.fit_box()


def test_removing_a_corner_refits_or_says_why_not(panorama_room: np.ndarray) -> None:
    scene = bpy.context.scene
    _click_all(panorama_room)
    scene.dimred_room.camera_height = 1.5
    bpy.ops.dimred.match_room()
    before = _vertices("Floor")
    bpy.ops.dimred.room_remove_corner(index=0)  # three corners left: a triangle that misses the probe
    assert "probe centre lies outside" in scene.dimred_room.problem
    assert np.array_equal(_vertices("Floor"), before)


def test_the_panel_draws_the_clicks_the_fit_and_the_picture(panorama_room: np.ndarray) -> None:
    from diminished_reality.panels import room as room_panel
    from tests.blender.test_registration import _draw

    _click_all(panorama_room)
    bpy.context.scene.dimred_room.camera_height = 1.5
    bpy.ops.dimred.match_room()
    drawn = _draw(room_panel.DIMRED_PT_room, bpy.context)
    assert {"operator dimred.room_click", "operator dimred.room_suggest", "operator dimred.match_room",
            "operator dimred.object_from_photo", "operator dimred.fit_box", "operator dimred.show_room_diagnostics",
            "prop camera_height", "prop manhattan"} <= set(drawn)
    assert drawn.count("prop point") == 4
    assert "label Camera 1.50 m, ceiling 2.50 m (camera height)" in drawn


def test_the_room_is_built_round_the_probe_centre_set(panorama_room: np.ndarray) -> None:
    scene = bpy.context.scene
    scene.dimred.probe_center, scene.dimred.use_probe_center = (1.0, -2.0, 5.0), True
    _click_all(panorama_room)
    scene.dimred_room.camera_height = 1.5
    bpy.ops.dimred.match_room()
    assert tuple(scene.dimred.probe_center) == pytest.approx((1.0, -2.0, 1.5))
    floor = _vertices("Floor")[:, :2]
    assert max(np.min(np.linalg.norm(floor - c - np.array([1.0, -2.0]), axis=1)) for c in BOX) < 0.1
