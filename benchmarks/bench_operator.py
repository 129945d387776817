"""How long Blender's main thread is blocked during a Remove from the UI.

Runs the Remove operator's background session (`operators.support.session.RemovalSession`) on a rendered
1024x512 scene the way the modal operator does: gather on the main thread, compute in the
worker thread, and poll it on a 0.05 s timer. Prints a table: the seconds of the gathering
step, the longest and mean main-thread time per timer tick, the longest gap between two ticks
(the main thread's worst stall, including any wait for the interpreter lock the worker holds),
the first preview's delay and the total run time. The target: no gap over 0.1 s beyond
the timer interval.
"""
from __future__ import annotations

import importlib.util
import itertools
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from addon.quality import DEFAULT_QUALITY  # noqa: E402
from rendered import arguments, open_scene  # noqa: E402

POLL_INTERVAL = 0.05


def _extension():
    spec = importlib.util.spec_from_file_location("diminished_reality", ROOT / "__init__.py",
                                                  submodule_search_locations=[str(ROOT)])
    module = importlib.util.module_from_spec(spec)
    sys.modules["diminished_reality"] = module
    spec.loader.exec_module(module)
    return module


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--quality", default=DEFAULT_QUALITY)
    args = ap.parse_args()
    spec, _ = open_scene(args)

    import bpy

    extension = _extension()
    extension.register()
    session_module = sys.modules["diminished_reality.operators.support.session"]
    settings = bpy.context.scene.dimred
    settings.target = bpy.data.objects[spec.remove]
    settings.quality = args.quality
    settings.output_dir = tempfile.mkdtemp(prefix="dimred-bench-")

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
    total = time.perf_counter() - t0
    if state != 'FINISHED':
        sys.exit(f"the removal failed: {session.message}")
    gaps = [b - a for a, b in itertools.pairwise(starts)]
    ticks = session.tick_seconds
    print(f"scene {args.scene} {args.width}x{args.width // 2}, quality {args.quality}, timer every {POLL_INTERVAL} s")
    print("| gather s | ticks | longest tick s | mean tick s | longest gap between ticks s "
          "| first preview s | total s |")
    print("|---|---|---|---|---|---|---|")
    print(f"| {gather:.3f} | {len(ticks)} | {max(ticks):.3f} | {sum(ticks) / len(ticks):.4f} | "
          f"{max(gaps):.3f} | {first_preview if first_preview is not None else float('nan'):.2f} | {total:.2f} |")
    extension.unregister()


if __name__ == "__main__":
    main()
