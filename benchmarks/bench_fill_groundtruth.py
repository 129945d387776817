"""The filled region on ground-truth scenes with tiled and planked floors, structure-aware fill
on and off, through the engine as the command line runs it (balanced, exact proxies):
    .venv/bin/python benchmarks/bench_fill_groundtruth.py [--scenes a,b] [--width 1024]
Prints a markdown table: structure (`scenes.metrics.structure_correlation` over the object's
pixels), detail ratio, mean ratio and object + shadow error (`hidden_region_scores`), NaNs,
the seconds the fill of the revealed surfaces took (`filled_surfaces` in the report), and the
report's stages `synthesis` (that fill and its previews) and `hidden_light` (the irradiance
after the removal at the revealed pixels).
Renders are cached (scenes.render); the first run renders what is missing (minutes each).
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

SCENES = "basic_box,wall_contact,far_dark_box,stool,warm_cylinder,demo"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=SCENES)
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--samples", type=int, default=16, help="Cycles samples (the demo always gets 32)")
    args = ap.parse_args()

    import bpy

    from addon.blender import reader
    from addon.pipeline import remove_object
    from scenes import metrics, spec
    from scenes.images import read_exr
    from scenes.render import render_pair

    print(f"{args.width}x{args.width // 2}, balanced, exact proxies")
    print()
    print("| scene | floor | structure-aware | structure | detail | mean | object + shadow | NaN | fill s "
          "| synthesis s | hidden light s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for name in args.scenes.split(","):
        s = spec.get(name)
        s = s.with_render(width=args.width, height=args.width // 2, samples=32 if name == "demo" else args.samples)
        paths = render_pair(s)
        bpy.ops.wm.open_mainfile(filepath=str(paths["blend"]))
        scene = reader.read_scene(bpy.context.scene)
        inp, truth, mask = read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"])
        for structure in (True, False):
            r = remove_object(scene, s.remove, quality="balanced", synth_structure=structure)
            edit = inp + r.difference
            h = metrics.hidden_region_scores(inp, edit, truth, mask)
            fill_s = sum(f["seconds"] for f in r.report["filled_surfaces"])
            print(f"| {name} | {s.room.floor.pattern} | {'on' if structure else 'off'} | {h['structure']:.3f} "
                  f"| {h['detail_ratio']:.2f} | {h['mean_ratio']:.3f} | {h['object_shadow_ratio']:.3f} "
                  f"| {int(np.isnan(edit).sum())} | {fill_s:.2f} | {r.report['seconds']['synthesis']:.2f} "
                  f"| {r.report['seconds']['hidden_light']:.2f} |", flush=True)


if __name__ == "__main__":
    main()
