"""Run time of a removal per stage and quality preset, on a rendered 1024x512 scene.

Prints a table: seconds per stage, the lighting error ratio against the Cycles truth, and the
hidden region's scores (`scenes.metrics.hidden_region_scores`).
The scene is the `basic_box` spec (a 0.5 m box) rendered at 1024x512; the render is cached
under .cache/groundtruth, so only the first run pays for Cycles. Timings on a shared machine
are noisy: compare presets within one run.
The table is also written into docs/results/bench_removal.md (`results.write`).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rendered import arguments, open_scene
from results import Table, write
from scenes import metrics


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--presets", default="draft,balanced,final")
    args = ap.parse_args()
    spec, paths = open_scene(args)

    import bpy

    from addon.blender import reader
    from addon.pipeline import remove_object
    from scenes.images import read_exr

    t0 = time.perf_counter()
    scene = reader.read_scene(bpy.context.scene)
    read_s = time.perf_counter() - t0
    inp, truth, mask = read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"])
    floor = metrics.noise_floor(inp, truth, mask)
    rows = []
    for preset in args.presets.split(","):
        r = remove_object(scene, spec.remove, quality=preset)
        ratio = metrics.lighting_error_ratio(inp, r.edited, truth, mask)
        rows.append((preset, r.report["seconds"], ratio, metrics.hidden_region_scores(inp, r.edited, truth, mask)))
    # Presets run different stages (a narrower working copy is downsampled and refined).
    stages = list(dict.fromkeys(k for _, sec, _, _ in rows for k in sec if k != "total"))
    table = Table(["preset", *stages, "total s", "error ratio", "hidden mean", "hidden detail", "object + shadow"],
                  title=f"scene {args.scene} {args.width}x{args.width // 2} @ {args.samples} spp; "
                        f"read_scene {read_s:.2f} s; noise floor {floor:.3f}")
    for preset, sec, ratio, hidden in rows:
        table.row(preset, *(f"{sec[k]:.2f}" if k in sec else "-" for k in stages), f"{sec['total']:.2f}",
                  f"{ratio:.3f}", f"{hidden['mean_ratio']:.3f}", f"{hidden['detail_ratio']:.2f}",
                  f"{hidden['object_shadow_ratio']:.3f}")
    write(table)


if __name__ == "__main__":
    main()
