"""The filled region on ground-truth scenes with tiled and planked floors, structure-aware fill
on and off, through the engine as the command line runs it (balanced, exact proxies):
    .venv/bin/python benchmarks/bench_fill_groundtruth.py [--scenes a,b] [--width 1024] [--samples 16]
Prints a markdown table: structure (`scenes.metrics.structure_correlation` over the object's
pixels) and beside it the same score of a second render of the truth (another seed: the render
noise alone, the ceiling of any fill's structure; `rendered.second_render_structure`), detail
ratio, mean ratio and object + shadow error (`hidden_region_scores`), NaNs,
the seconds the fill of the revealed surfaces took (`filled_surfaces` in the report), and the
report's stages `synthesis` (that fill and its previews) and `hidden_light` (the irradiance
after the removal at the revealed pixels).
Renders are cached (scenes.render); the first run renders what is missing (minutes each).
The table is also written into docs/results/bench_fill_groundtruth.md (`results.write`).
"""
from __future__ import annotations

import numpy as np

from rendered import FLOOR_SCENES, ground_truths, scene_list_arguments, second_render_structure
from results import Table, write


def main() -> None:
    args = scene_list_arguments(__doc__, FLOOR_SCENES)

    from addon.pipeline import remove_object
    from scenes import metrics

    table = Table(["scene", "floor", "structure-aware", "structure", "second render", "detail", "mean",
                   "object + shadow", "NaN", "fill s", "synthesis s", "hidden light s"],
                  title=f"{args.width}x{args.width // 2} at {args.samples} samples, balanced, exact proxies")
    for gt in ground_truths(args):
        s = gt.spec
        ceiling = second_render_structure(gt)
        for structure in (True, False):
            r = remove_object(gt.scene, s.remove, quality="balanced", synth_structure=structure)
            edit = gt.input + r.difference
            h = metrics.hidden_region_scores(gt.input, edit, gt.truth, gt.mask)
            fill_s = sum(f["seconds"] for f in r.report["filled_surfaces"])
            table.row(s.name, s.room.floor.pattern, "on" if structure else "off", f"{h['structure']:.3f}",
                      f"{ceiling:.3f}", f"{h['detail_ratio']:.2f}", f"{h['mean_ratio']:.3f}",
                      f"{h['object_shadow_ratio']:.3f}", int(np.isnan(edit).sum()), f"{fill_s:.2f}",
                      f"{r.report['seconds']['synthesis']:.2f}", f"{r.report['seconds']['hidden_light']:.2f}")
    write(table)


if __name__ == "__main__":
    main()
