"""Removal with rough proxies: what each error of a proxy modelled by eye costs, per scene.

The render of each scene used the exact object; for each case the pair's scene.blend is copied
with the proxy off by the case (`scenes.perturb`: a shift in x/y, a turn about the vertical, a
uniform scale, a floor modelled too high, or the object's bounding box for it: a box for a
chair) and the object removed through `python -m addon.cli remove`, with `--cli-args` appended
(e.g. "--align"). Columns, against the Cycles render without the object: total
(`object_shadow_ratio`, the error left over the object and its shadow), lighting
(`lighting_error_ratio`), ghost (`ghost_share`, the object's pixels left visibly wrong), far
damage, pixels with a NaN, the command's seconds, and, where the report holds an alignment, the
pose error it leaves (`pose_error`). Each case's row gives its difference to the scene's exact
row; a last table sums the cases up over the scenes. Both are written into
docs/results/bench_rough_proxies.md. Renders are cached under .cache/groundtruth
(the missing ones are rendered first, about a minute each at 1024x512 and 16 samples).
"""
from __future__ import annotations

import argparse
import json
import math
import shlex
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from results import Table, write
from scenes import spec as scene_specs
from scenes.perturb import CaseResult, ProxyError, parse, run_case
from scenes.render import render_pair

SCENES = ("basic_box", "wall_contact", "stool", "red_box", "far_dark_box", "tall_cabinet", "warm_cylinder")
CASES = ("exact", "shift 2 cm x", "shift 2 cm y", "shift 5 cm at 45 deg", "turn 5 deg", "turn -5 deg", "scale 0.95",
         "scale 1.05", "floor +1 cm", "shift 3 cm at 45 deg + turn 3 deg + scale 0.97", "box")
COLUMNS = ("scene", "case", "total", "Δ total", "lighting", "Δ lighting", "ghost", "Δ ghost", "far", "NaN", "s",
           "pose left (cm, deg, %)", "failure")
SCORES = ("total", "lighting", "ghost")


def _arguments() -> argparse.Namespace:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=",".join(SCENES), help="comma-separated scene names")
    ap.add_argument("--size", type=int, default=1024, help="panorama width (height = width / 2)")
    ap.add_argument("--samples", type=int, default=16, help="Cycles samples per pixel of the renders")
    ap.add_argument("--quality", default="balanced")
    ap.add_argument("--cases", default=",".join(CASES),
                    help="comma-separated proxy errors, each as scenes.perturb spells them; exact is always run first")
    ap.add_argument("--cli-args", default="", help="appended to every remove command, e.g. \"--align\"")
    ap.add_argument("--json", type=Path, metavar="FILE", help="also write every row to FILE")
    # argparse takes a value that starts with "--" (--cli-args "--align") for an option of its own.
    argv, given = [], iter(sys.argv[1:])
    for a in given:
        argv.append(f"--cli-args={next(given, '')}" if a == "--cli-args" else a)
    return ap.parse_args(argv)


def _row(scene: str, r: CaseResult, exact: CaseResult) -> dict:
    row = {"scene": scene, "case": r.error.name, **{k: getattr(r, k) for k in (*SCORES, "far", "nans", "seconds")}}
    row.update({f"d_{k}": getattr(r, k) - getattr(exact, k) for k in SCORES})
    return {**row, "pose": r.pose, "failure": r.failure}


def _cells(row: dict) -> list[str]:
    exact = row["case"] == "exact"
    pose = row["pose"]
    return [row["scene"], row["case"],
            *[c for k in SCORES for c in (f"{row[k]:.3f}", "" if exact else f"{row['d_' + k]:+.3f}")],
            f"{row['far']:.3f}", str(row["nans"]), f"{row['seconds']:.1f}",
            "—" if pose is None else f"{pose['shift_cm']:.1f}, {pose['turn_deg']:.1f}, {pose['scale_percent']:.1f}",
            row["failure"] or ""]


def _summary(rows: list[dict]) -> Table:
    """Per case over the scenes: mean and worst difference of the total to the exact proxy's,
    mean ghost difference, worst far damage, NaN pixels and failed runs."""
    table = Table(("case", "mean Δ total", "worst Δ total", "mean Δ ghost", "worst far", "NaN", "failed"),
                  title="Per case over the scenes")
    for case in dict.fromkeys(r["case"] for r in rows if r["case"] != "exact"):
        of = [r for r in rows if r["case"] == case]
        ok = [r for r in of if r["failure"] is None]
        d_total, d_ghost = [r["d_total"] for r in ok], [r["d_ghost"] for r in ok]
        table.row(case, f"{_mean(d_total):+.3f}", f"{max(d_total, default=math.nan):+.3f}", f"{_mean(d_ghost):+.3f}",
                  f"{max((r['far'] for r in ok), default=math.nan):.3f}", sum(r["nans"] for r in ok), len(of) - len(ok))
    return table


def _mean(values: list[float]) -> float:
    return sum(values) / len(values) if values else math.nan


def _finite(value):
    """JSON has no NaN: a failed run's scores are written as null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return {k: _finite(v) for k, v in value.items()} if isinstance(value, dict) else value


def main() -> None:
    args = _arguments()
    specs = [scene_specs.get(n).with_render(width=args.size, height=args.size // 2, samples=args.samples)
             for n in args.scenes.split(",") if n]
    errors = [parse(c) for c in args.cases.split(",") if c.strip()]
    errors = [ProxyError(), *(e for e in dict.fromkeys(errors) if e != ProxyError())]
    cli_args = shlex.split(args.cli_args)
    pairs = {spec.name: render_pair(spec) for spec in specs}
    table = Table(COLUMNS, title=f"{args.size}x{args.size // 2} @ {args.samples} spp, quality {args.quality}, "
                                 f"cli args {' '.join(cli_args) or '(none)'}; Δ: the case minus the exact proxy")
    rows = []
    for spec in specs:
        exact = None
        for error in errors:
            with tempfile.TemporaryDirectory(prefix="rough.") as work:
                result = run_case(pairs[spec.name], spec.remove, error, work, quality=args.quality,
                                  cli_args=cli_args)
            exact = exact or result
            rows.append(_row(spec.name, result, exact))
            table.row(*_cells(rows[-1]))
    write(table, _summary(rows))
    if args.json:
        args.json.write_text(json.dumps({"size": args.size, "samples": args.samples, "quality": args.quality,
                                         "cli_args": cli_args, "rows": [_finite(r) for r in rows]}, indent=1))


if __name__ == "__main__":
    main()
