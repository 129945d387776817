"""Subprocesses that render with Cycles, run by `scenes.render` so that Blender's state and
crashes stay out of the caller.

`python -m scenes.render_job pair DIR` renders one ground-truth pair. DIR holds `spec.json`;
the job writes there `input.exr` (with the object to remove), `truth.exr` (without it, same
seed), `scene.blend` (the user's view of the scene: the proxy geometry, `ProbeCenter`, and a
world showing input.exr), `mask.npy` (pixels whose centre direction from the probe sees the
removed object) and `times.json` (wall and CPU seconds per render). A `truth.exr` already in
DIR is kept and not rendered.

`python -m scenes.render_job world BLEND OUT.exr` renders only the world of a saved scene, as
a user's panoramic camera at the probe centre sees it: rotation (90, 0, -90) degrees, one point
sample per pixel centre, the Environment Texture switched to Closest interpolation. It checks
that the pair's panorama, through the world's Mapping node, lands where the scene is.
"""
from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import bpy
import numpy as np

from .build import build, set_black_world, set_environment_world, use_mask_materials
from .images import read_exr, write_exr
from .spec import SceneSpec


def _render(scene: bpy.types.Scene, path: Path) -> np.ndarray:
    """Render the active camera to a scratch EXR at `path`; return its (H, W, 3) pixels, top
    row first, and delete the file."""
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    pixels = read_exr(path)
    path.unlink()
    return pixels


def _timed_render(scene: bpy.types.Scene, path: Path, times: dict[str, float],
                  name: str) -> np.ndarray:
    wall, cpu = time.perf_counter(), time.process_time()
    pixels = _render(scene, path)
    times[name] = round(time.perf_counter() - wall, 3)
    times[f"{name}_cpu"] = round(time.process_time() - cpu, 3)
    return pixels


def run_pair(out: Path) -> None:
    spec = SceneSpec.from_json((out / "spec.json").read_text())
    bpy.ops.wm.read_factory_settings(use_empty=True)
    build(spec)
    scene = bpy.context.scene
    removed = bpy.data.objects[spec.remove]
    times: dict[str, float] = {}

    write_exr(out / "input.exr", _timed_render(scene, out / "raw.exr", times, "input"))
    if not (out / "truth.exr").exists():  # else `scenes.render` copied another pair's, the same
        removed.hide_render = True
        write_exr(out / "truth.exr", _timed_render(scene, out / "raw.exr", times, "truth"))
        removed.hide_render = False

    set_environment_world(scene, str(out / "input.exr"), spec.world_rotation_z)
    scene["groundtruth_spec"] = spec.to_json()
    scene.render.filepath = "//render.exr"
    bpy.ops.wm.save_as_mainfile(filepath=str(out / "scene.blend"), relative_remap=True)

    # Only camera rays matter: one point sample per pixel centre, emission only.
    set_black_world(scene)
    use_mask_materials(scene, spec.remove)
    scene.cycles.samples = 1
    scene.cycles.max_bounces = 0
    mask = _timed_render(scene, out / "raw.exr", times, "mask")[..., 0] > 0.5
    np.save(out / "mask.npy", mask)
    (out / "times.json").write_text(json.dumps(times, indent=1))


def run_world(blend: Path, out_exr: Path) -> None:
    bpy.ops.wm.open_mainfile(filepath=str(blend))
    scene = bpy.context.scene
    for obj in scene.objects:
        obj.hide_render = obj.type != "CAMERA"
    scene.camera.rotation_euler = (math.pi / 2, 0.0, -math.pi / 2)
    for node in scene.world.node_tree.nodes:
        if node.bl_idname == "ShaderNodeTexEnvironment":
            node.interpolation = "Closest"
    scene.cycles.samples = 1
    scene.cycles.max_bounces = 0
    write_exr(out_exr, _render(scene, out_exr.with_suffix(".raw.exr")))


if __name__ == "__main__":
    if sys.argv[1:2] == ["pair"] and len(sys.argv) == 3:
        run_pair(Path(sys.argv[2]))
    elif sys.argv[1:2] == ["world"] and len(sys.argv) == 4:
        run_world(Path(sys.argv[2]), Path(sys.argv[3]))
    else:
        sys.exit("usage: python -m scenes.render_job pair DIR | world BLEND OUT.exr")
