"""Behaviour check for a change that must not change any result: run every ground-truth scene
through the command line and compare two such runs.

    .venv/bin/python scripts/compare_runs.py run DIR       # removals and relocations into DIR/<case>/
    .venv/bin/python scripts/compare_runs.py compare A B   # difference images within 1e-6 relative,
                                                           # reports equal but for seconds

Run `run` at the commit before a change (in a `git worktree` sharing `.cache/`, so the renders
are reused) and at the commit after, then `compare` the two folders.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from scenes import spec as scene_specs  # noqa: E402
from scenes.images import read_exr  # noqa: E402
from scenes.render import render_pair  # noqa: E402

REMOVALS = [(name, "balanced") for name in (
    "basic_box", "red_box", "stool", "wall_contact", "bright_lamp", "seam", "rotated_world", "second_object",
    "tiny_lamp", "dark_floor", "white_floor", "zenith", "grazing", "shadowed_box", "demo")]
REMOVALS += [("nadir", "draft"), ("stool", "final"), ("red_box", "draft")]
# Several objects removed in order, each from what the ones before left (the composition).
COMPOSED = [("second_object", ("Box", "Cabinet"))]
RELOCATIONS = [("basic_box", 40.0, 1.3), ("stool", 40.0, 1.3), ("rotated_world", -40.0, 1.3),
               ("wall_contact", -40.0, 1.3), ("red_box", 25.0, 0.8), ("second_object", -40.0, 1.3),
               ("bright_lamp", 40.0, 1.3), ("seam", 40.0, 1.3), ("nadir", 40.0, 1.3), ("shadowed_box", 60.0, 1.2)]


def _cases() -> list[tuple[str, list[str]]]:
    cases = []
    for name, quality in REMOVALS:
        spec = scene_specs.get(name)
        blend = str(render_pair(spec)["blend"])
        cases.append((f"remove-{name}-{quality}",
                      ["remove", blend, "--object", spec.remove, "--quality", quality]))
    for name, objects in COMPOSED:
        blend = str(render_pair(scene_specs.get(name))["blend"])
        cases.append((f"remove-{name}-{'-'.join(objects)}",
                      ["remove", blend, *(a for o in objects for a in ("--object", o))]))
    for name, yaw, scale in RELOCATIONS:
        spec = scene_specs.get(name)
        blend = str(render_pair(spec)["blend"])
        cases.append((f"relocate-{name}-{yaw:g}-{scale:g}",
                      ["relocate", blend, "--object", spec.remove, "--yaw", str(yaw), "--distance-scale", str(scale)]))
    return cases


def run(out: Path) -> int:
    failed = 0
    for case, arguments in _cases():
        target = out / case
        proc = subprocess.run([sys.executable, "-m", "addon.cli", *arguments, "--out", str(target)],
                              cwd=REPO, capture_output=True, text=True)
        print(f"{case}: exit {proc.returncode}", flush=True)
        if proc.returncode:
            failed += 1
            print(proc.stderr[-2000:], file=sys.stderr)
    return 1 if failed else 0


def _without_seconds(report: object) -> object:
    """`report` without its timings: every "seconds" key, at any depth (a stage's, a filled
    surface's, each of several removals')."""
    if isinstance(report, dict):
        return {k: _without_seconds(v) for k, v in report.items() if k != "seconds"}
    if isinstance(report, list):
        return [_without_seconds(v) for v in report]
    return report


def compare(before: Path, after: Path) -> int:
    bad = 0
    for folder in sorted(p for p in before.iterdir() if p.is_dir()):
        other = after / folder.name
        a = read_exr(folder / "difference.exr")
        b = read_exr(other / "difference.exr")
        scale = max(float(np.abs(a).max()), 1e-30)
        deviation = float(np.abs(a - b).max()) / scale
        ra = json.loads((folder / "report.json").read_text())
        rb = json.loads((other / "report.json").read_text())
        same_report = _without_seconds(ra) == _without_seconds(rb)
        same_stages = set(ra["seconds"]) == set(rb["seconds"])
        ok = deviation <= 1e-6 and same_report and same_stages
        bad += not ok
        print(f"{folder.name:40s} deviation {deviation:.1e}  report {'equal' if same_report else 'DIFFERS'}"
              f"  stages {'equal' if same_stages else 'DIFFER'}  {'ok' if ok else 'FAIL'}")
        if not same_report:
            for key in sorted(set(ra) | set(rb)):
                if key != "seconds" and _without_seconds(ra.get(key)) != _without_seconds(rb.get(key)):
                    print(f"    {key}: {ra.get(key)!r} != {rb.get(key)!r}"[:400])
    print(f"{bad} of the cases differ")
    return 1 if bad else 0


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("run").add_argument("out", type=Path)
    both = sub.add_parser("compare")
    both.add_argument("before", type=Path)
    both.add_argument("after", type=Path)
    args = parser.parse_args()
    return run(args.out) if args.command == "run" else compare(args.before, args.after)


if __name__ == "__main__":
    sys.exit(main())
