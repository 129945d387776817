"""Plot of `bench_tradeoff.py`'s table: lighting error ratio against seconds, one point per
setting, the Pareto front joined and the Monte Carlo noise floor (and twice it) drawn.

Runs in `.venv-bench/` (matplotlib): `./dev bench-tradeoff` measures, then calls this.
Usage: plot_tradeoff.py out/tradeoff/tradeoff.csv [out.png]
"""
from __future__ import annotations

import csv
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main(argv: list[str]) -> None:
    source = Path(argv[0])
    target = Path(argv[1]) if len(argv) > 1 else source.with_suffix(".png")
    with open(source, newline="") as handle:
        rows = [r for r in csv.DictReader(handle) if r["width"] == "256"]
    seconds = [float(r["total_s"]) for r in rows]
    error = [float(r["lighting_ratio"]) for r in rows]
    floor = sum(float(r["noise_floor"]) for r in rows) / len(rows)
    fig, ax = plt.subplots(figsize=(8, 5), dpi=110)
    ax.scatter(seconds, error, s=18, color="tab:blue", zorder=3)
    # The one-parameter sweeps crowd around the balanced preset: name the presets and the front.
    for r, x, y in zip(rows, seconds, error, strict=True):
        if r["pareto"] == "True" or r["setting"] in ("draft", "balanced", "final"):
            ax.annotate(r["setting"], (x, y), fontsize=8, xytext=(4, 4), textcoords="offset points")
    front = sorted((x, y) for r, x, y in zip(rows, seconds, error, strict=True) if r["pareto"] == "True")
    ax.plot(*zip(*front, strict=True), color="tab:red", lw=1.5, label="Pareto front", zorder=2)
    ax.axhline(floor, color="grey", ls=":", label=f"noise floor {floor:.3f}")
    ax.axhline(2 * floor, color="grey", ls="--", label="2 x noise floor")
    ax.set_xscale("log")
    ax.set_xlabel("seconds per removal (mean over the scenes, 256x128, log scale)")
    ax.set_ylabel("lighting error ratio (mean)")
    ax.set_title("Removal: error against run time")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(target)
    print(f"wrote {target}")


if __name__ == "__main__":
    main(sys.argv[1:])
