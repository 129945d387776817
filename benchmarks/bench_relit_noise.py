"""The relit shadows' noise, matched to their surface's (`match_relit_noise`) and not, on the
ground-truth scenes, through the engine as the command line runs it (balanced, exact proxies):
    .venv/bin/python benchmarks/bench_relit_noise.py [--scenes a,b] [--width 1024]
Prints a markdown table: the pixels the truth shows at least 1.5 times brighter than the input
outside the object, their relative detail edit / truth (`scenes.metrics.relit_detail_ratio`:
1 = the lit surface's, above = the shadow's noise relit with it) with the match off and on,
the object + shadow error (`hidden_region_scores`) off and on, the growth k the stage measured
per surface and its seconds.
Renders are cached (scenes.render); the first run renders what is missing (minutes each).
The table is also written into docs/results/bench_relit_noise.md (`results.write`).
"""
from __future__ import annotations

from rendered import FLOOR_SCENES, ground_truths, scene_list_arguments
from results import Table, write


def main() -> None:
    args = scene_list_arguments(__doc__, FLOOR_SCENES)

    from addon.pipeline import remove_object
    from scenes import metrics

    table = Table(["scene", "relit pixels", "relit detail off", "on", "object + shadow off", "on", "growth k",
                   "stage s"],
                  title=f"{args.width}x{args.width // 2}, balanced, exact proxies")
    for gt in ground_truths(args):
        s = gt.spec
        row = []
        for match in (False, True):
            r = remove_object(gt.scene, s.remove, quality="balanced", match_relit_noise=match)
            edit = gt.input + r.difference
            detail, pixels = metrics.relit_detail_ratio(gt.input, edit, gt.truth, gt.mask)
            shadow = metrics.hidden_region_scores(gt.input, edit, gt.truth, gt.mask)["object_shadow_ratio"]
            row.append((detail, shadow))
        growth = ", ".join(f"{k:.2f}" for k in r.report["relit_noise"]["growth"].values()) or "-"
        table.row(s.name, pixels, f"{row[0][0]:.2f}", f"{row[1][0]:.2f}", f"{row[0][1]:.3f}", f"{row[1][1]:.3f}",
                  growth, f"{r.report['seconds']['relit_noise']:.3f}")
    write(table)


if __name__ == "__main__":
    main()
