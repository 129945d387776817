"""The ground-truth harness: specs, the built scenes, tiny cached render pairs, and the
panorama convention (camera, formula and the world's Environment Texture agree)."""
from __future__ import annotations

import dataclasses
import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from scenes import metrics as M
from scenes import spec as S
from scenes.images import read_exr
from scenes.render import REPO, load_pair, render_pair, render_world

# 70 degrees of world rotation is exactly 14 columns at this width, so the rotated and the
# plain panoramas are whole-pixel shifts of each other and can be compared bit for bit.
W, H = 72, 36
# Few bounces: these tests check the harness (files, seeding, masks), not the light transport.
TINY = {"width": W, "height": H, "samples": 16, "max_bounces": 8}


def _py(code: str) -> str:
    """Run `code` in a fresh interpreter (bpy state never enters pytest); return its stdout."""
    proc = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    return proc.stdout


@pytest.fixture(scope="module")
def basic() -> S.SceneSpec:
    return S.get("basic_box").with_render(**TINY)


@pytest.fixture(scope="module")
def rotated() -> S.SceneSpec:
    return S.get("rotated_world").with_render(**TINY)


# --- specs (no rendering) -------------------------------------------------------------------

ALL_SPECS = {**S.SPECS, **S.PHOTO_SPECS, **S.HELD_OUT_SPECS}


def test_spec_json_round_trip_and_key() -> None:
    for spec in ALL_SPECS.values():
        again = S.SceneSpec.from_json(spec.to_json())
        assert again == spec and again.key() == spec.key()
    base = S.get("basic_box")
    assert base.with_render(samples=5).key() != base.key()
    assert S.get("rotated_world").key() != base.key()
    assert len({s.key() for s in ALL_SPECS.values()}) == len(ALL_SPECS)


def test_fields_added_for_photo_rooms_leave_the_other_keys_alone() -> None:
    # Left out of the JSON at their default, and their build code hashed only into the keys of
    # the scenes that use them: the older scenes' cached renders stay valid.
    for spec in S.SPECS.values():
        text = spec.to_json()
        assert not spec.extended()
        assert not any(f'"{name}"' in text for name in ("windows", "photo", "wall_photo", "seat_height"))
    for spec in S.PHOTO_SPECS.values():
        assert spec.extended() and spec.room.floor.photo is not None
        plain = dataclasses.replace(spec, windows=(), room=dataclasses.replace(
            spec.room, floor=S.Floor(), wall_photo=None), objects=tuple(
            dataclasses.replace(o, kind="box", seat_height=None) for o in spec.objects))
        assert not plain.extended()


def test_held_out_scenes_move_only_the_object_of_a_photo_room() -> None:
    # Each stands in a tuned scene's room, under its lamps and windows, with the same object
    # elsewhere: what differs is where the fill's rules meet the floor.
    assert not set(S.HELD_OUT_SPECS) & (set(S.SPECS) | set(S.PHOTO_SPECS))
    rooms = {(s.room, s.lamps, s.windows) for s in S.PHOTO_SPECS.values()}
    placements = {(s.removed_object().location, s.removed_object().rotation_z) for s in S.PHOTO_SPECS.values()}
    for spec in S.HELD_OUT_SPECS.values():
        assert (spec.room, spec.lamps, spec.windows) in rooms
        assert (spec.removed_object().location, spec.removed_object().rotation_z) not in placements
        assert S.get(spec.name) is spec


def test_spec_validation() -> None:
    base = S.get("basic_box")
    with pytest.raises(ValueError, match="remove"):
        S.SceneSpec(**{**base.__dict__, "remove": "Nothing"})
    with pytest.raises(ValueError, match="probe"):
        S.SceneSpec(**{**base.__dict__, "probe": (10.0, 0.0, 1.5)})
    with pytest.raises(ValueError, match="used by the room"):
        floor = S.SceneObject("Floor", "box", (1.0, 1.0, 1.0), (0.0, 0.0, 0.0))
        S.SceneSpec(**{**base.__dict__, "objects": (floor,), "remove": "Floor"})
    with pytest.raises(KeyError, match="known"):
        S.get("no_such_scene")
    photo = S.get("hotel_chair")
    with pytest.raises(ValueError, match="photo"):
        S.SceneSpec(**{**photo.__dict__, "room": dataclasses.replace(photo.room, floor=S.Floor("photo"))})
    with pytest.raises(ValueError, match="window"):
        w = dataclasses.replace(photo.windows[0], center=(2.3, 1.4))
        S.SceneSpec(**{**photo.__dict__, "windows": (w,)})
    with pytest.raises(ValueError, match="seat height"):
        chair = dataclasses.replace(photo.objects[0], seat_height=None)
        S.SceneSpec(**{**photo.__dict__, "objects": (chair,)})


def test_named_specs_are_varied() -> None:
    assert {"basic_box", "red_box", "stool", "wall_contact", "bright_lamp", "seam", "nadir",
            "rotated_world", "second_object", "demo"} <= set(S.SPECS)
    assert {s.room.floor.pattern for s in ALL_SPECS.values()} == set(S.FLOOR_PATTERNS)
    assert {o.kind for s in ALL_SPECS.values() for o in s.objects} == set(S.OBJECT_KINDS)
    photo = S.PHOTO_SPECS.values()
    assert len({s.room.floor.photo.source for s in photo}) >= 5
    assert {w.wall for s in photo for w in s.windows} == set(S.WALLS)
    assert any(w.sun_strength > 0 for s in photo for w in s.windows)
    assert {s.removed_object().kind for s in photo} == {"box", "stool", "chair"}
    strengths = [lamp.strength for lamp in S.get("bright_lamp").lamps]
    assert max(strengths) >= 1000 * min(strengths)


@pytest.mark.slow
def test_every_named_spec_builds() -> None:
    out = _py(
        "import json, bpy\n"
        "from scenes import spec, build\n"
        "res = {}\n"
        "for name, s in spec.SPECS.items():\n"
        "    bpy.ops.wm.read_factory_settings(use_empty=True)\n"
        "    build.build(s)\n"
        "    res[name] = sorted(o.name for o in bpy.context.scene.objects)\n"
        "print(json.dumps(res))\n")
    built = json.loads(out.strip().splitlines()[-1])
    for name, spec in S.SPECS.items():
        names = set(built[name])
        assert {"Floor", "Ceiling", "ProbeCenter", "ProbeCamera", "Wall.East", "Wall.West",
                "Wall.North", "Wall.South"} <= names
        assert {o.name for o in spec.objects} <= names
        n = len(spec.lamps)
        assert {f"Lamp.{i:03d}" for i in range(1, n + 1)} <= names
        assert {f"LampHousing.{i:03d}" for i in range(1, n + 1)} <= names


@pytest.mark.slow
def test_every_photo_room_builds() -> None:
    out = _py(
        "import json, bpy\n"
        "from scenes import spec, build_extended\n"
        "res = {}\n"
        "for name, s in spec.PHOTO_SPECS.items():\n"
        "    bpy.ops.wm.read_factory_settings(use_empty=True)\n"
        "    build_extended.build(s)\n"
        "    objects = bpy.context.scene.objects\n"
        "    floor = objects['Floor'].active_material.node_tree.nodes\n"
        "    images = [n.image for n in floor if n.bl_idname == 'ShaderNodeTexImage']\n"
        "    walls = [o for o in objects if o.name.startswith('Wall.')]\n"
        "    textured = [any(n.bl_idname == 'ShaderNodeTexImage' for n in o.active_material.node_tree.nodes)\n"
        "                for o in walls]\n"
        "    res[name] = {'names': sorted(o.name for o in objects),\n"
        "                 'faces': {o.name: len(o.data.polygons) for o in objects if o.type == 'MESH'},\n"
        "                 'floor_image': [(i.size[0], i.size[1], i.packed_file is not None) for i in images],\n"
        "                 'walls_textured': textured}\n"
        "print(json.dumps(res))\n")
    built = json.loads(out.strip().splitlines()[-1])
    for name, spec in S.PHOTO_SPECS.items():
        names, faces = set(built[name]["names"]), built[name]["faces"]
        assert {o.name for o in spec.objects} | {"Floor", "Ceiling", "Wall.North", "Wall.South"} <= names
        # The photograph's texture, packed, one texel per `texel` metres of floor.
        photo, (x0, y0, _), (x1, y1, _) = spec.room.floor.photo, spec.room.lo, spec.room.hi
        assert built[name]["floor_image"] == [[round((x1 - x0) / photo.texel), round((y1 - y0) / photo.texel), True]]
        assert built[name]["walls_textured"] == [spec.room.wall_photo is not None] * 4
        for k, window in enumerate(spec.windows, start=1):
            assert {f"Window.{k:03d}", f"WindowHousing.{k:03d}"} <= names
            assert (f"Sun.{k:03d}" in names) == (window.sun_strength > 0)
            # The wall around the hole: 3 x 3 cells less the window's.
            assert faces[f"Wall.{window.wall.capitalize()}"] == 8
        for o in spec.objects:
            # A chair: seat, four legs (the rear two rising to the top) and the back's rest.
            assert o.kind != "chair" or faces[o.name] == 6 * 6


# --- a tiny render pair ---------------------------------------------------------------------

@pytest.mark.slow
def test_pair_files_and_linear_output(basic: S.SceneSpec) -> None:
    paths = render_pair(basic)
    assert all(p.exists() for p in paths.values())
    assert paths["input"].parent.name == basic.key()
    inp, truth, mask = load_pair(basic)
    assert inp.shape == truth.shape == (H, W, 3) and inp.dtype == np.float32
    assert mask.shape == (H, W) and mask.dtype == bool
    # Pixels that see a lamp show its radiance exactly: no view transform, no clamping.
    assert inp.max() == pytest.approx(max(lamp.strength for lamp in basic.lamps))
    assert render_pair(basic) == paths  # cached


def test_an_object_moved_keeps_the_truth_key() -> None:
    base = S.get("basic_box")
    moved = S.relocated(base, 40.0, 1.3)
    assert moved.key() != base.key() and moved.truth_key() == base.truth_key()
    assert base.with_render(samples=5).truth_key() != base.truth_key()
    assert S.get("seam").truth_key() != base.truth_key()


@pytest.mark.slow
def test_a_moved_pair_takes_the_truth_of_the_pair_it_moves(basic: S.SceneSpec) -> None:
    """Its truth is copied, not rendered again: the same file, bit for bit."""
    inp, truth, mask = load_pair(basic)
    moved = render_pair(S.relocated(basic, 40.0, 1.3))
    assert "truth" not in json.loads(moved["times"].read_text())
    assert np.array_equal(read_exr(moved["truth"]), truth)
    assert not np.array_equal(read_exr(moved["input"]), inp) and not (np.load(moved["mask"]) == mask).all()


@pytest.mark.slow
def test_input_and_truth_differ_near_the_object_only(basic: S.SceneSpec) -> None:
    inp, truth, mask = load_pair(basic)
    yi, yt = M.luminance(inp), M.luminance(truth)
    rel = np.abs(yi - yt) / yt
    near, far = M.dilate(mask, 4) & ~mask, ~M.dilate(mask, 12)
    assert rel[mask].mean() > 0.2
    assert rel[near].mean() > 3 * rel[far].mean()
    # Same seed: where no path touched the box the two renders are identical.
    assert np.median(rel[far]) == 0.0
    # The box's shadow: without it the floor around it is brighter.
    assert (yt - yi)[near].sum() > 0


def _pixel_of(direction: np.ndarray) -> tuple[float, float]:
    """(row, column) of a direction with u = 0.5 - atan2(y, x) / 2pi, v = 1 - acos(z) / pi."""
    x, y, z = direction / np.linalg.norm(direction)
    u = 0.5 - math.atan2(y, x) / (2 * math.pi)
    v = 1.0 - math.acos(z) / math.pi
    return (1.0 - v) * H - 0.5, u * W - 0.5


@pytest.mark.slow
@pytest.mark.parametrize("name", ["basic_box", "seam", "nadir"])
def test_mask_is_where_the_formula_puts_the_object(name: str) -> None:
    scene = S.get(name).with_render(**TINY)
    _, _, mask = load_pair(scene)
    obj = scene.removed_object()
    centre = np.array(obj.location) + np.array([0.0, 0.0, obj.size[2] / 2]) - np.array(scene.probe)
    row, col = _pixel_of(centre)
    assert mask[round(row), round(col) % W]
    rows, cols = np.nonzero(mask)
    # Columns are angles: average them on the circle so a region across the seam works.
    angle = np.angle(np.exp(2j * np.pi * (cols + 0.5) / W).mean())
    mean_col = (angle / (2 * np.pi) * W - 0.5) % W
    assert abs(rows.mean() - row) < 1.0
    assert abs((mean_col - col + W / 2) % W - W / 2) < 1.0
    if name == "seam":
        assert mask[:, 0].any() and mask[:, -1].any()


@pytest.mark.slow
def test_scene_blend_is_the_users_scene(basic: S.SceneSpec, rotated: S.SceneSpec) -> None:
    code = (
        "import json, sys, bpy\n"
        "res = {}\n"
        "for path in sys.argv[1:]:\n"
        "    bpy.ops.wm.open_mainfile(filepath=path)\n"
        "    sc = bpy.context.scene\n"
        "    nodes = {n.bl_idname: n for n in sc.world.node_tree.nodes}\n"
        "    env = nodes['ShaderNodeTexEnvironment']\n"
        "    m = nodes.get('ShaderNodeMapping')\n"
        "    res[path] = dict(\n"
        "        image=bpy.path.abspath(env.image.filepath),\n"
        "        space=env.image.colorspace_settings.name,\n"
        "        interp=env.interpolation, size=list(env.image.size),\n"
        "        feeds_bg=env.outputs['Color'].links[0].to_node.bl_idname,\n"
        "        rot=list(m.inputs['Rotation'].default_value) if m else None,\n"
        "        mtype=m.vector_type if m else None,\n"
        "        coords=m.inputs['Vector'].links[0].from_socket.name if m else None,\n"
        "        probe=list(sc.objects['ProbeCenter'].location),\n"
        "        objects=sorted(o.name for o in sc.objects))\n"
        "print(json.dumps(res))\n")
    blends = [str(render_pair(s)["blend"]) for s in (basic, rotated)]
    proc = subprocess.run([sys.executable, "-c", code, *blends], cwd=REPO, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    res = json.loads(proc.stdout.strip().splitlines()[-1])
    for spec, blend in zip((basic, rotated), blends, strict=True):
        r = res[blend]
        assert Path(r["image"]).resolve() == render_pair(spec)["input"].resolve()
        assert r["space"] in ("Linear Rec.709", "Non-Color") and r["interp"] == "Linear"
        assert r["size"] == [W, H] and r["feeds_bg"] == "ShaderNodeBackground"
        assert r["probe"] == pytest.approx(spec.probe)
        assert spec.remove in r["objects"] and "Floor" in r["objects"]
    assert res[blends[0]]["rot"] is None
    assert res[blends[1]]["rot"] == pytest.approx([0.0, 0.0, math.radians(70.0)])
    assert res[blends[1]]["mtype"] == "POINT" and res[blends[1]]["coords"] == "Generated"


@pytest.mark.slow
def test_world_reproduces_the_scene(basic: S.SceneSpec, rotated: S.SceneSpec,
                                    tmp_path: Path) -> None:
    """A user's panoramic camera at the probe centre sees, through the world's Environment
    Texture (Closest) and Mapping node, exactly the panorama the pair was rendered as, with the
    scene's geometry in the same pixels as in the unrotated scene."""
    plain = render_pair(basic)
    world = render_world(plain["blend"], tmp_path / "plain.exr")
    assert np.array_equal(world, read_exr(plain["input"]))

    turned = render_pair(rotated)
    shift = round(rotated.world_rotation_z / 360.0 * W)
    world = render_world(turned["blend"], tmp_path / "turned.exr")
    assert np.array_equal(world, np.roll(read_exr(turned["input"]), shift, axis=1))
    # The rotated panorama holds the same room shifted: geometry seen by the user's camera
    # through the Mapping node lands where the plain scene has it.
    assert np.array_equal(np.load(turned["mask"]), np.roll(np.load(plain["mask"]), -shift, axis=1))
