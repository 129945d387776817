"""Window-lit rooms, checked against physics: the object's shadow of a window and of the sun
through it is removed, and mixing the soft shadow from cells of pixels
(`addon/removal/shadow_cells.py`) loses nothing against computing every pixel's shadow.

The room is photo-textured (`scenes.spec.PHOTO_SPECS`): a window in a wall with a sun patch
inside it, ceiling lamps, a chair with legs. It is rendered at 512x256 (32 samples, cached):
the cells are at most an eighth of the object's radius wide, so at 256x128 the chair's shadows
would all be computed pixel by pixel.
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from test_removal_groundtruth import BOUND

from scenes import metrics as M
from scenes import spec as S
from scenes.images import read_exr
from scenes.render import REPO, render_pair

SCENES = ["hotel_chair"]
SIZE = {"width": 512, "height": 256, "samples": 32}
# Removes an object from a .blend in-process with parameter overrides (the command line takes
# presets only): argv blend, object, overrides as JSON, difference .npy, report .json.
_REMOVE = """
import json, sys
import bpy
import numpy as np
from addon.blender import reader
from addon.pipeline import remove_object
bpy.ops.wm.open_mainfile(filepath=sys.argv[1])
result = remove_object(reader.read_scene(bpy.context.scene), sys.argv[2], quality="balanced",
                       **json.loads(sys.argv[3]))
np.save(sys.argv[4], result.difference)
with open(sys.argv[5], "w") as f:
    json.dump({"shadow_cells": result.report.get("shadow_cells"), "exact_pairs": result.report.get("exact_pairs")}, f)
"""


def _removed(blend, name: str, overrides: dict, out) -> tuple[np.ndarray, dict]:
    out.mkdir()
    proc = subprocess.run([sys.executable, "-c", _REMOVE, str(blend), name, json.dumps(overrides),
                           str(out / "difference.npy"), str(out / "report.json")],
                          cwd=REPO, capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return np.load(out / "difference.npy"), json.loads((out / "report.json").read_text())


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENES)
def test_a_window_shadow_is_removed_and_its_cells_cost_no_accuracy(name: str, tmp_path) -> None:
    spec = S.get(name).with_render(**SIZE)
    paths = render_pair(spec)
    inp, truth, mask = read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"])
    cells, report = _removed(paths["blend"], spec.remove, {}, tmp_path / "cells")
    exact, _ = _removed(paths["blend"], spec.remove, {"shadow_cell": 1}, tmp_path / "exact")
    with_cells = M.lighting_error_ratio(inp, inp + cells, truth, mask)
    every_pixel = M.lighting_error_ratio(inp, inp + exact, truth, mask)
    floor = M.noise_floor(inp, truth, mask)
    print(f"{name}: light error ratio {with_cells:.4f} with cells, {every_pixel:.4f} every pixel computed "
          f"(noise floor {floor:.3f}); {report}")
    assert report["shadow_cells"]["interpolated_points"] > 0
    assert with_cells <= BOUND + floor
    assert with_cells <= every_pixel + 0.01
