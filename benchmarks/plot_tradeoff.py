"""Plot of `bench_tradeoff.py`'s table: lighting error ratio against seconds, one point per
setting, the Pareto front joined and the Monte Carlo noise floor (and twice it) drawn.

Runs in `.venv-bench/` (matplotlib): `./dev bench-tradeoff` measures, then calls this.
Usage: plot_tradeoff.py out/tradeoff/tradeoff.csv [out.png] [--width 256] [--seconds total_s]
With rows of several scenes at that width (`tradeoff_scenes.csv`, or the `--wide` rows) each
scene gets its colour and its own noise floor.
"""
from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main(argv: list[str]) -> None:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("source", type=Path)
    ap.add_argument("target", type=Path, nargs="?")
    ap.add_argument("--width", default="256", help="plot the rows of this panorama width")
    ap.add_argument("--seconds", default="total_s", choices=("total_s", "cpu_s"),
                    help="wall-clock or CPU seconds (steadier on a shared machine)")
    args = ap.parse_args(argv)
    target = args.target or args.source.with_suffix(".png")
    with open(args.source, newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if r["width"] == args.width]
    scenes = list(dict.fromkeys(r["scenes"] for r in rows))
    fig, ax = plt.subplots(figsize=(8 + 3 * (len(scenes) > 1), 5), dpi=110)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i, scene in enumerate(scenes):
        colour = colours[i % len(colours)]
        group = [r for r in rows if r["scenes"] == scene]
        seconds = [float(r[args.seconds]) for r in group]
        error = [float(r["lighting_ratio"]) for r in group]
        name = scene if len(scenes) > 1 else None
        ax.scatter(seconds, error, s=18, color=colour, zorder=3, label=name)
        # The one-parameter sweeps (NAME=VALUE) crowd around the balanced preset: name the
        # presets (and other settings without a value) and the front.
        for r, x, y in zip(group, seconds, error, strict=True):
            if r["pareto"] == "True" or "=" not in r["setting"]:
                ax.annotate(r["setting"], (x, y), fontsize=8, xytext=(4, 4), textcoords="offset points")
        front = sorted((x, y) for r, x, y in zip(group, seconds, error, strict=True) if r["pareto"] == "True")
        if front:
            ax.plot(*zip(*front, strict=True), color="tab:red", lw=1.5, label="Pareto front", zorder=2)
        floor = sum(float(r["noise_floor"]) for r in group) / len(group)
        ax.axhline(floor, color=colour if name else "grey", ls=":", lw=1,
                   label=f"noise floor {floor:.3f}" + (f" ({scene})" if name else ""))
        if not name:
            ax.axhline(2 * floor, color="grey", ls="--", label="2 x noise floor")
    ax.set_xscale("log")
    what = "CPU seconds" if args.seconds == "cpu_s" else "seconds"
    per = "per scene" if len(scenes) > 1 else "mean over the scenes"
    ax.set_xlabel(f"{what} per removal ({per}, {args.width}x{int(args.width) // 2}, log scale)")
    ax.set_ylabel("lighting error ratio" + ("" if len(scenes) > 1 else " (mean)"))
    ax.set_title("Removal: error against run time")
    # A legend of several scenes would hide points: it goes beside the axes.
    ax.legend(fontsize=8, **({"loc": "upper left", "bbox_to_anchor": (1.01, 1.0)} if len(scenes) > 1 else {}))
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(target)
    print(f"wrote {target}")


if __name__ == "__main__":
    main(sys.argv[1:])
