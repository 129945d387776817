"""Error against run time: the removal over a sweep of the parameters that trade one for the other.

For each setting (the three presets, then the balanced preset with one parameter changed at a
time) the removal runs on the cached ground-truth scenes; the script measures the lighting error
ratio against the Cycles truth (region A, `scenes.metrics.lighting_error_ratio`) and its Monte
Carlo noise floor (`noise_floor`: the error left when the input is scaled by the 3x3 box-filtered
ratio of truth to input), the hidden region's scores, and the seconds of the lighting stages and
of the synthesis, the CPU seconds of the process (steadier than the wall clock on a shared
machine) and its peak resident memory during the removal (Linux only; Blender and the loaded
scene included). The panorama resolution is swept on the 0.5 m box (256x128 and 1024x512).
It writes `out/tradeoff/tradeoff.csv` and prints its table, also written into
docs/results/bench_tradeoff.md (a row per setting, means over the scenes, the Pareto front of
error against total seconds marked; `out/tradeoff/tradeoff_scenes.csv` has a row per scene and
setting);
`benchmarks/plot_tradeoff.py` draws the plot from the CSV.

`--settings` picks the sweep's settings: labels of SETTINGS or `PRESET[+NAME=VALUE...]`
(`balanced+sender_samples=6+reach=0.05`); `--wide SCENE:SAMPLES,...` and `--wide-settings`
choose what runs at `--width` (an empty `--scenes` skips the 256x128 sweep), e.g.
`--scenes "" --wide basic_box:16,bright_lamp:16,demo:32 --wide-settings balanced,final`.
"""
from __future__ import annotations

import csv
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rendered import arguments, open_scene
from results import Table, write
from scenes import metrics

SCENES = ("basic_box", "red_box", "wall_contact", "stool")
# (label, preset, overrides): each sweep changes one parameter of the balanced preset.
SETTINGS = (
    ("draft", "draft", {}),
    ("balanced", "balanced", {}),
    ("final", "final", {}),
    ("patches=200", "balanced", {"patches": 200}),
    ("patches=1200", "balanced", {"patches": 1200}),
    ("max_senders=8", "balanced", {"max_senders": 8}),
    ("max_senders=64", "balanced", {"max_senders": 64}),
    ("sender_samples=2", "balanced", {"sender_samples": 2}),
    ("sender_samples=6", "balanced", {"sender_samples": 6}),
    ("fine_cells=2", "balanced", {"fine_cells": 2.0}),
    ("fine_cells=5", "balanced", {"fine_cells": 5.0}),
    ("significance=0.03", "balanced", {"significance": 0.03}),
    ("significance=0.003", "balanced", {"significance": 0.003}),
    ("max_bounces=2", "balanced", {"max_bounces": 2}),
    ("raster_cell=1.4", "balanced", {"raster_cell": 1.4}),
    ("raster_cell=0.5", "balanced", {"raster_cell": 0.5}),
    ("synth_levels=2", "balanced", {"synth_levels": 2}),
    ("synth_generations=1", "balanced", {"synth_generations": 1}),
    ("synth_generations=3", "balanced", {"synth_generations": 3}),
    ("synth_neighbourhood=5", "balanced", {"synth_neighbourhood": 5}),
    ("synth_neighbourhood=9", "balanced", {"synth_neighbourhood": 9}),
)
RESOLUTION_SETTINGS = ("draft", "balanced")
FIELDS = ("setting", "scenes", "width", "lighting_ratio", "noise_floor", "ratio_over_floor", "hidden_mean",
          "hidden_detail", "object_shadow", "lighting_s", "synthesis_s", "total_s", "cpu_s", "peak_gb", "pareto")
_KB = 1024


def setting(text: str) -> tuple[str, str, dict]:
    """(label, preset, overrides) of a label of SETTINGS or of `PRESET[+NAME=VALUE...]`."""
    known = {s[0]: s for s in SETTINGS}
    if text in known:
        return known[text]
    preset, *pairs = text.split("+")
    overrides = {}
    for pair in pairs:
        name, _, value = pair.partition("=")
        overrides[name] = int(value) if value.lstrip("-").isdigit() else float(value)
    return text, preset, overrides


def _reset_peak() -> None:
    """Start a new peak of resident memory (writing 5 to clear_refs resets VmHWM on Linux)."""
    try:
        Path("/proc/self/clear_refs").write_text("5")
    except OSError:
        pass


def _peak_gb() -> float:
    """Peak resident memory since `_reset_peak`, in GB; NaN where /proc does not say."""
    try:
        lines = Path("/proc/self/status").read_text().splitlines()
    except OSError:
        return float("nan")
    peak = [int(line.split()[1]) for line in lines if line.startswith("VmHWM:")]
    return peak[0] * _KB / 1e9 if peak else float("nan")


def _measure(scene_name: str, width: int, samples: int, settings) -> list[dict]:
    """Rows of one scene: every setting's scores and seconds."""
    import bpy

    from addon.blender import reader
    from addon.pipeline import remove_object
    from scenes.images import read_exr

    args = arguments("").parse_args(["--scene", scene_name, "--width", str(width), "--samples", str(samples)])
    spec, paths = open_scene(args)
    scene = reader.read_scene(bpy.context.scene)
    inp, truth, mask = read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"])
    floor = metrics.noise_floor(inp, truth, mask)
    rows = []
    for label, preset, overrides in settings:
        _reset_peak()
        t0, c0 = time.perf_counter(), time.process_time()
        result = remove_object(scene, spec.remove, quality=preset, **overrides)
        total, cpu = time.perf_counter() - t0, time.process_time() - c0
        peak = _peak_gb()
        seconds = result.report["seconds"]
        hidden = metrics.hidden_region_scores(inp, result.edited, truth, mask)
        synthesis = seconds.get("synthesis", 0.0)
        rows.append(dict(setting=label, scenes=scene_name, width=width,
                         lighting_ratio=metrics.lighting_error_ratio(inp, result.edited, truth, mask),
                         noise_floor=floor,
                         hidden_mean=hidden["mean_ratio"], hidden_detail=hidden["detail_ratio"],
                         object_shadow=hidden["object_shadow_ratio"], lighting_s=total - synthesis,
                         synthesis_s=synthesis, total_s=total, cpu_s=cpu, peak_gb=peak))
        del result
        print(f"  {scene_name} {width}: {label}: ratio {rows[-1]['lighting_ratio']:.3f}, {total:.1f} s, "
              f"{cpu:.1f} cpu s, {peak:.2f} GB", flush=True)
    return rows


def _mean_rows(rows: list[dict], width: int) -> list[dict]:
    """One row per setting: means over the scenes measured at `width`."""
    out = []
    labels = list(dict.fromkeys(r["setting"] for r in rows if r["width"] == width))
    for label in labels:
        group = [r for r in rows if r["setting"] == label and r["width"] == width]
        row = {k: float(np.mean([r[k] for r in group])) for k in FIELDS[3:-1] if k != "ratio_over_floor"}
        row["ratio_over_floor"] = row["lighting_ratio"] / row["noise_floor"]
        out.append(dict(setting=label, scenes="+".join(r["scenes"] for r in group), width=width, **row))
    return out


def pareto(rows: list[dict], *, cost: str = "total_s", error: str = "lighting_ratio") -> None:
    """Mark the rows no other row beats in both `cost` and `error` (row["pareto"])."""
    for row in rows:
        row["pareto"] = not any(o[cost] <= row[cost] and o[error] <= row[error]
                                and (o[cost] < row[cost] or o[error] < row[error]) for o in rows)


def table(rows: list[dict], title: str) -> Table:
    table = Table(("setting", "scenes", "width", "lighting error ratio", "noise floor", "ratio / floor", "hidden mean",
                   "hidden detail", "object + shadow", "lighting s", "synthesis s", "total s", "CPU s", "peak GB",
                   "Pareto"), title=title)
    for r in rows:
        table.row(r["setting"], r["scenes"], r["width"], f"{r['lighting_ratio']:.3f}", f"{r['noise_floor']:.3f}",
                  f"{r['ratio_over_floor']:.2f}", f"{r['hidden_mean']:.3f}", f"{r['hidden_detail']:.2f}",
                  f"{r['object_shadow']:.3f}", f"{r['lighting_s']:.2f}", f"{r['synthesis_s']:.2f}",
                  f"{r['total_s']:.2f}", f"{r['cpu_s']:.2f}", f"{r['peak_gb']:.2f}", "yes" if r["pareto"] else "")
    return table


def _write_csv(path: Path, rows: list[dict]) -> None:
    with open(path, "w", newline="") as handle:
        writer = csv.DictWriter(handle, FIELDS)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.4f}" if isinstance(v, float) else v) for k, v in row.items()})


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--out", default="out/tradeoff")
    ap.add_argument("--scenes", default=",".join(SCENES), help="the 256x128 sweep's scenes ('' for none)")
    ap.add_argument("--settings", default=",".join(s[0] for s in SETTINGS),
                    help="the sweep's settings: labels of SETTINGS or PRESET[+NAME=VALUE...]")
    ap.add_argument("--wide", default="basic_box:16", help="SCENE:SAMPLES,... measured at --width")
    ap.add_argument("--wide-settings", default=",".join(RESOLUTION_SETTINGS), help="settings measured at --width")
    args = ap.parse_args()
    started = time.perf_counter()
    rows: list[dict] = []
    for name in filter(None, args.scenes.split(",")):
        rows += _measure(name, 256, 64, [setting(t) for t in args.settings.split(",")])
    table_rows = _mean_rows(rows, 256)
    pareto(table_rows)
    wide = []
    for item in filter(None, args.wide.split(",")):
        name, _, samples = item.partition(":")
        wide += _measure(name, args.width, int(samples or args.samples),
                         [setting(t) for t in args.wide_settings.split(",")])
    for row in rows + wide:
        row["ratio_over_floor"] = row["lighting_ratio"] / row["noise_floor"]
        row["pareto"] = False
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    _write_csv(out / "tradeoff.csv", table_rows + wide)
    _write_csv(out / "tradeoff_scenes.csv", rows + wide)
    write(table(table_rows + wide, f"Means over {args.scenes or 'no scenes'} at 256x128 (64 spp), then "
                                   f"{args.wide or 'nothing'} at {args.width}x{args.width // 2} (SCENE:spp); "
                                   f"{time.perf_counter() - started:.0f} s in all."))

if __name__ == "__main__":
    main()
