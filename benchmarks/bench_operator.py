"""How long Blender's main thread is blocked during a Remove from the UI, and how soon the first
preview shows.

Runs the Remove operator's background session (`operators.support.session.RemovalSession`) on a
rendered scene the way the modal operator does: gather on the main thread, compute in the worker
thread, and poll it on a 0.05 s timer. `--panorama-width` larger than the render's `--width`
upsamples the render (each pixel repeated) into a temporary EXR that the world shows. With the
small copy of the panorama made first (`--cache warm`, as marking the object does) or not at all
(`cold`: the run reads the panorama before its first preview). `--until-preview` cancels the run
once the first preview shows (for panoramas whose whole run takes minutes).

Prints a table: the seconds of the gathering step, the longest and mean main-thread time per
timer tick, the longest gap between two ticks (the main thread's worst stall, including any wait
for the interpreter lock the worker holds), the first preview's delay from the start of the
gathering (the operator's invoke) to the tick that put it in the world, and the total run time.
The target: no gap over 0.1 s beyond the timer interval, the first preview within 0.5 s.
The table is also written into docs/results/bench_operator.md (`results.write`).
"""
from __future__ import annotations

import importlib.util
import itertools
import shutil
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.quality import DEFAULT_QUALITY  # noqa: E402
from rendered import arguments, open_scene  # noqa: E402
from results import Table, write  # noqa: E402

POLL_INTERVAL = 0.05


def _extension():
    spec = importlib.util.spec_from_file_location("diminished_reality", ROOT / "__init__.py",
                                                  submodule_search_locations=[str(ROOT)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["diminished_reality"] = module
    spec.loader.exec_module(module)
    return module


def _upsampled(scene, width: int, folder: str) -> None:
    """Make the world show its image upsampled to `width` (a multiple of its own)."""
    from addon.blender import reader
    from addon.io.exr import read_exr, write_exr

    image = reader.environment_texture(scene).image
    world = read_exr(reader.read_scene(scene, defer_file=True).hdri_path)
    factor = width // world.shape[1]
    path = str(Path(folder) / f"world_{width}.exr")
    write_exr(path, np.repeat(np.repeat(world, factor, axis=0), factor, axis=1))
    del world
    image.filepath = path
    image.reload()


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--quality", default=DEFAULT_QUALITY)
    ap.add_argument("--panorama-width", type=int, default=0,
                    help="upsample the render to this width (a multiple of --width); default: the render's")
    ap.add_argument("--cache", choices=("warm", "cold"), default="warm")
    ap.add_argument("--until-preview", action="store_true", help="cancel the run once the first preview shows")
    args = ap.parse_args()
    if args.panorama_width and args.panorama_width % args.width:
        ap.error("--panorama-width must be a multiple of --width")
    spec, _ = open_scene(args)

    import bpy

    folder = tempfile.mkdtemp(prefix="dimred-bench-")
    extension = _extension()
    extension.register()
    session_module = sys.modules["diminished_reality.operators.support.session"]
    warmup = sys.modules["diminished_reality.operators.support.warmup"]
    warmup.folder = lambda: str(Path(folder) / "cache")
    if args.panorama_width > args.width:
        _upsampled(bpy.context.scene, args.panorama_width, folder)
    settings = bpy.context.scene.dimred
    settings.target = bpy.data.objects[spec.remove]  # as marking it does: starts the small copy
    settings.quality = args.quality
    settings.output_dir = folder
    making = warmup.running(warmup.panorama_file(bpy.context.scene))
    if making is not None:
        making.join()
    if args.cache == "cold":
        shutil.rmtree(Path(folder) / "cache", ignore_errors=True)

    t0 = time.perf_counter()
    session = session_module.RemovalSession.begin(bpy.context)
    gather = time.perf_counter() - t0
    session.start()
    starts, first_preview = [], None
    state = 'RUNNING'
    while state == 'RUNNING':
        time.sleep(POLL_INTERVAL)
        starts.append(time.perf_counter())
        state = session.tick(bpy.context)
        if first_preview is None and bpy.data.images.get(session_module.PREVIEW_IMAGE) is not None:
            first_preview = time.perf_counter() - t0
            if args.until_preview:
                session.cancel(bpy.context)
                state = 'CANCELLED'
    total = time.perf_counter() - t0
    if state != 'FINISHED' and not args.until_preview:
        sys.exit(f"the removal failed: {session.message}")
    gaps = [b - a for a, b in itertools.pairwise(starts)] or [float("nan")]
    ticks = session.tick_seconds
    width = args.panorama_width or args.width
    table = Table(["gather s", "ticks", "longest tick s", "mean tick s", "longest gap between ticks s",
                   "first preview s", "total s"],
                  title=f"scene {args.scene} {width}x{width // 2}, quality {args.quality}, small copy {args.cache}, "
                        f"timer every {POLL_INTERVAL} s{', until the first preview' if args.until_preview else ''}")
    table.row(f"{gather:.3f}", len(ticks), f"{max(ticks):.3f}", f"{sum(ticks) / len(ticks):.4f}", f"{max(gaps):.3f}",
              f"{first_preview if first_preview is not None else float('nan'):.2f}", f"{total:.2f}")
    write(table)
    extension.unregister()
    shutil.rmtree(folder, ignore_errors=True)


if __name__ == "__main__":
    main()
