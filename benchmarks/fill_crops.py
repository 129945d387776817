"""Crops of ground-truth scenes where the object stood: before | truth | ours | ours per-pixel |
PatchMatch, for docs/design.md (docs/images/fill_<scene>.png).

Two steps, because PatchMatch lives in the benchmark environment and the removal in Blender's:
    .venv/bin/python benchmarks/fill_crops.py ours demo,basic_box,stool      (renders if not cached)
    .venv-bench/bin/python benchmarks/fill_crops.py compare demo,basic_box,stool
The first writes out/crops/<scene>.npz (8-bit crops, display-referred: the panorama scaled to its
99th percentile there and gamma 2.2, as a 2D tool gets a photograph); the second fills the
object's pixels of the 'before' crop with PatchMatch (patch radius 3, seed 0) and writes the
picture, each crop enlarged 3 times.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
OUT = ROOT / "out" / "crops"
SCALE = 3


def _u8(img: np.ndarray, white: float) -> np.ndarray:
    return (np.clip(img / white, 0, 1) ** (1 / 2.2) * 255 + 0.5).astype(np.uint8)


def ours(names: list[str]) -> None:
    import bpy

    from addon.blender import reader
    from addon.pipeline import remove_object
    from scenes import spec as scene_specs
    from scenes.images import read_exr
    from scenes.render import render_pair

    OUT.mkdir(parents=True, exist_ok=True)
    for name in names:
        spec = scene_specs.get(name).with_render(width=1024, height=512, samples=32 if name == "demo" else 16)
        paths = render_pair(spec)
        bpy.ops.wm.open_mainfile(filepath=str(paths["blend"]))
        scene = reader.read_scene(bpy.context.scene)
        inp, truth, mask = read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"])
        edits = [inp + remove_object(scene, spec.remove, quality="balanced", synth_structure=s).difference
                 for s in (True, False)]
        ys, xs = np.nonzero(mask)
        pad = max(np.ptp(ys), np.ptp(xs)) // 3 + 4
        box = (slice(max(ys.min() - pad, 0), ys.max() + pad), slice(max(xs.min() - pad, 0), xs.max() + pad))
        white = float(np.percentile(truth[box], 99))
        np.savez(OUT / f"{name}.npz", before=_u8(inp[box], white), truth=_u8(truth[box], white),
                 ours=_u8(edits[0][box], white), per_pixel=_u8(edits[1][box], white), mask=mask[box])
        print(f"{name}: crops in {OUT / (name + '.npz')}", flush=True)


def compare(names: list[str]) -> None:
    import patchmatch
    from PIL import Image

    for name in names:
        d = np.load(OUT / f"{name}.npz")
        patchmatch.set_random_seed(0)
        pm = patchmatch.inpaint(d["before"], d["mask"].astype(np.uint8) * 255, patch_size=3)
        panels = [d["before"], d["truth"], d["ours"], d["per_pixel"], pm]
        gap = np.full((panels[0].shape[0], 4, 3), 255, np.uint8)
        row = np.concatenate([x for p in panels for x in (p, gap)][:-1], axis=1)
        row = row.repeat(SCALE, 0).repeat(SCALE, 1)
        path = ROOT / "docs" / "images" / f"fill_{name}.png"
        Image.fromarray(row).save(path)
        print(f"{name}: {path}", flush=True)


if __name__ == "__main__":
    {"ours": ours, "compare": compare}[sys.argv[1]](sys.argv[2].split(","))
