"""The README demo: render the `demo` room, remove its box with the command line, compare;
then move the box elsewhere in the panorama.

    .venv/bin/python scripts/demo.py [--width 1024] [--samples N] [--quality balanced]
                                     [--yaw 40] [--distance-scale 1.3]

Renders (or reuses from .cache/groundtruth) the demo room with and without the box, runs
`python -m addon.cli remove scene.blend --object Box --out out/demo/removal` exactly as a user
would, then writes into out/demo/: before.exr, after.exr (the edited panorama), difference.exr,
truth.exr and side_by_side.png (before / after / truth, top to bottom, tonemapped alike), and
prints the scores of scenes.metrics. Then `python -m addon.cli relocate ... --yaw 40
--distance-scale 1.3 --out out/demo/relocation` moves the box: relocated.exr and
relocated.png (before / relocated; the relocation's own ground-truth scores are in the tests
and benchmarks/bench_relocation.py).
"""
from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

from addon.quality import DEFAULT_QUALITY, DESCRIPTIONS  # noqa: E402
from scenes import metrics, spec  # noqa: E402
from scenes.images import auto_exposure, read_exr, tonemap, write_png  # noqa: E402
from scenes.render import pair_paths, render_pair  # noqa: E402

OUT = REPO / "out" / "demo"


def _side_by_side(panels: list[np.ndarray], exposure: float) -> np.ndarray:
    gap = np.full((6, panels[0].shape[1], 3), 255, np.uint8)
    rows = [tonemap(p, exposure) for p in panels]
    return np.concatenate([rows[0], gap, rows[1], gap, rows[2]], axis=0)


def main() -> int:
    demo = spec.get("demo")
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--width", type=int, default=demo.render.width,
                        help="panorama width in pixels (height = width / 2)")
    parser.add_argument("--samples", type=int, default=demo.render.samples,
                        help="Cycles samples per pixel")
    parser.add_argument("--quality", default=DEFAULT_QUALITY, choices=tuple(DESCRIPTIONS))
    parser.add_argument("--yaw", type=float, default=40.0, help="the relocation's yaw in degrees")
    parser.add_argument("--distance-scale", type=float, default=1.3, help="the relocation's distance factor")
    args = parser.parse_args()
    scene = demo.with_render(width=args.width, height=args.width // 2, samples=args.samples)

    cached = pair_paths(scene)["times"].exists()
    print(f"demo room {args.width}x{args.width // 2}, {args.samples} samples"
          f"{' (cached)' if cached else ': rendering with and without the box...'}", flush=True)
    paths = render_pair(scene)
    times = json.loads(paths["times"].read_text())
    print("  render seconds: " + ", ".join(
        f"{k} {times[k]:.1f} ({times[k + '_cpu']:.0f} CPU)" for k in ("input", "truth", "mask") if k in times))

    OUT.mkdir(parents=True, exist_ok=True)
    # A failed run must not leave an older run's results looking current.
    for stale in ("after.exr", "difference.exr", "side_by_side.png", "relocated.exr", "relocated.png"):
        (OUT / stale).unlink(missing_ok=True)
    shutil.copyfile(paths["input"], OUT / "before.exr")
    shutil.copyfile(paths["truth"], OUT / "truth.exr")
    removal = OUT / "removal"
    seconds = _command(["remove", str(paths["blend"]), "--object", scene.remove, "--out", str(removal),
                        "--quality", args.quality])
    if seconds is None:
        return 1
    shutil.copyfile(removal / "edited.exr", OUT / "after.exr")
    shutil.copyfile(removal / "difference.exr", OUT / "difference.exr")

    before, truth, mask = read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"])
    after = read_exr(OUT / "after.exr")
    panels = _side_by_side([before, after, truth], auto_exposure(before))
    write_png(OUT / "side_by_side.png", panels)
    report = json.loads((removal / "report.json").read_text())
    scores = metrics.summary(before, after, truth, mask)
    total = report.get("seconds", {}).get("total", float("nan"))
    print(f"  removal took {seconds:.1f} s (report total {total:.1f} s)")
    for item in report.get("skipped", []):
        print(f"  skipped {item.get('stage')}: {item.get('reason')}")
    for warning in report.get("warnings", []):
        print(f"  warning: {warning}")
    print(f"  lighting error ratio {scores['lighting_error_ratio']:.3f} "
          f"(1 = unedited, 0 = truth; noise floor {scores['noise_floor']:.3f}) "
          f"over {scores['region_pixels']} px")
    print(f"  far damage {scores['far_damage']:+.4f} (<= 0: nothing made worse away from the box)")
    print(f"  colour error {scores['bleeding_input']:.4f} before -> "
          f"{scores['bleeding_edit']:.4f} after")

    relocation = OUT / "relocation"
    seconds = _command(["relocate", str(paths["blend"]), "--object", scene.remove, "--out", str(relocation),
                        "--quality", args.quality, "--yaw", str(args.yaw),
                        "--distance-scale", str(args.distance_scale)])
    if seconds is None:
        return 1
    shutil.copyfile(relocation / "edited.exr", OUT / "relocated.exr")
    moved = read_exr(OUT / "relocated.exr")
    gap = np.full((6, before.shape[1], 3), 255, np.uint8)
    exposure = auto_exposure(before)
    write_png(OUT / "relocated.png", np.concatenate([tonemap(before, exposure), gap, tonemap(moved, exposure)]))
    moved_report = json.loads((relocation / "report.json").read_text())
    rel = moved_report["relocation"]
    print(f"  relocation took {seconds:.1f} s: yaw {rel['yaw']:.1f} deg, distance x{rel['distance_scale']:.2f}, "
          f"view elevation change {rel['elevation_change']:+.1f} deg, standing on {', '.join(rel['support'])}")
    for warning in moved_report.get("warnings", []):
        print(f"  warning: {warning}")
    print(f"wrote {', '.join(sorted(p.name for p in OUT.iterdir() if p.is_file()))} in {OUT}")
    return 0


def _command(arguments: list[str]) -> float | None:
    """Run `python -m addon.cli ARGUMENTS` as a user would; its seconds, or None (reported) on failure."""
    cmd = [sys.executable, "-m", "addon.cli", *arguments]
    print("  $ python " + " ".join(cmd[1:]), flush=True)
    t = time.perf_counter()
    proc = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True)
    seconds = time.perf_counter() - t
    if proc.returncode != 0:
        tail = "\n".join((proc.stdout + proc.stderr).strip().splitlines()[-15:])
        print(f"error: the {arguments[0]} command failed (exit {proc.returncode}) after {seconds:.1f} s. "
              f"Its output ends:\n{tail}", file=sys.stderr)
        return None
    return seconds


if __name__ == "__main__":
    sys.exit(main())
