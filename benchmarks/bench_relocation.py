"""Run time of a relocation per quality preset, on a rendered 1024x512 scene, with its error.

Prints a table: seconds of the removal at the old place and of the insertion passes, the
relocation error ratio against the Cycles render with the object at its new place
(`scenes.metrics.relocation_error_ratio` over both objects and both shadows), the same ratio of
the best edit smooth at the 3 px scale (the truth's noise), the far damage, and the insertion's
last residual. Default: `basic_box`, 40 degrees, distance x1.3 (the first move of the relocation
ground-truth tests). Renders are cached under .cache/groundtruth; timings on a shared machine are
noisy: compare within one run.
The table is also written into docs/results/bench_relocation.md (`results.write`).
"""
from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rendered import arguments, open_scene
from results import Table, write
from scenes import metrics
from scenes import spec as scene_specs
from scenes.render import load_pair


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--presets", default="draft,balanced,final")
    ap.add_argument("--yaw", type=float, default=40.0)
    ap.add_argument("--distance-scale", type=float, default=1.3)
    args = ap.parse_args()
    spec = scene_specs.get(args.scene).with_render(width=args.width, height=args.width // 2, samples=args.samples)
    # Both renders first: Cycles runs in a subprocess, before Blender opens the scene here.
    truth, _, new_mask = load_pair(scene_specs.relocated(spec, args.yaw, args.distance_scale))
    spec, _ = open_scene(args)

    import bpy

    from addon.blender import reader
    from addon.pipeline import relocate_object
    from addon.relocation.fixedview import Move

    inp, empty, old_mask = load_pair(spec)
    scene = reader.read_scene(bpy.context.scene)
    region = metrics.relocation_region(inp, truth, empty, old_mask, new_mask)
    floor = metrics.noise_floor(inp, truth, old_mask | new_mask, region)
    table = Table(["preset", "removal s", "insertion s", "total s", "error ratio", "far damage"],
                  title=f"scene {args.scene} {args.width}x{args.width // 2} @ {args.samples} spp; "
                        f"yaw {args.yaw} x{args.distance_scale}; region {int(region.sum())} px; "
                        f"noise floor {floor:.3f}")
    for preset in args.presets.split(","):
        t0 = time.perf_counter()
        r = relocate_object(scene, spec.remove, Move(args.yaw, args.distance_scale), quality=preset)
        total = time.perf_counter() - t0
        sec = r.report["seconds"]
        removal = sum(v for k, v in sec.items() if k.startswith("removal_"))
        error = metrics.relocation_error_ratio(inp, r.edited, truth, region)
        far = metrics.far_damage(inp, r.edited, truth, old_mask | new_mask, region=region)
        table.row(preset, f"{removal:.2f}", f"{total - removal:.2f}", f"{total:.2f}", f"{error:.3f}", f"{far:.3f}")
    write(table)


if __name__ == "__main__":
    main()
