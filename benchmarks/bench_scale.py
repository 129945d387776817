"""Seconds and peak memory of a removal per panorama size and per object triangle count.

    .venv/bin/python benchmarks/bench_scale.py [--sizes 1024,2048,4096,8192,16384]
        [--splits 1,9,29,64] [--quality draft,balanced,final] [--engine]
        [--truth-sizes 2048] [--scene basic_box] [--width 1024] [--samples 8]
        [--working-widths 512,1024,2048] [--rooms hotel_chair,interior] [--repeat 1]

Each row is one removal in a fresh process, measured from outside: wall seconds from its
start to its exit and its peak resident memory (that child's rusage). By default the process
is the command line as a user runs it (`python -m addon.cli remove SCENE.blend --object NAME
--out DIR --quality Q`): bpy's start, opening the .blend, reading the panorama's EXR and writing
the result's EXRs are part of the cost. With --engine it is the engine alone on the same input:
the panorama read from its EXR, the geometry from an array file, no bpy, only the report written.

The scene is rendered with Cycles at --width and at each of --truth-sizes (pairs cached under
.cache/groundtruth; a missing one takes minutes); rows of a rendered size score the edit
against the render without the object. Every other size is the --width render upsampled (each
pixel repeated), fine for timing. The triangle counts come from splitting each of the removed
object's triangles into k^2 at --width (the same surface, so the same truth): k = 1, 9, 29, 64
give the box's 12, 972, 10092 and 49152 triangles. Each row's .blend (with the upsampled EXR
as its world image, or the split mesh) is built once by a bpy subprocess and cached under
.cache/bench_scale. The ratio columns divide by the row of the --width panorama with k = 1 of
the same preset (and working width) in the same run; --working-widths repeats each preset's
rows with the light solved at those widths (`--working-width`), default the preset's own.
--rooms adds rows of other rooms at --width, divided by the same row: a scene spec rendered
(hotel_chair: a photo-textured room lit through a window with a sun patch, a chair with legs)
and `interior`, Blender's hotel-room photograph with its room and armchair built from the
committed click file. The targets are 8K within 3x the 1K time and 3 GB, 16K within 8 GB,
200k triangles within 2x the 12-triangle time, and the window-lit room and the photograph
within 2x the box's. Timings on a shared machine are noisy: compare the rows of
one run, and with --repeat N keep each row's fastest of N runs. Under the table, the floor
the largest panorama's rows compare against: what reading
its EXR, one numpy pass over its pixels and writing it once cost in this process. The table is
printed and written into docs/results/bench_scale.md.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from addon.io import exr
from addon.run_memory import run_memory
from rendered import arguments
from results import Table, write
from scenes import metrics
from scenes import spec as scene_specs
from scenes.images import read_exr
from scenes.render import REPO, render_pair

CACHE = REPO / ".cache" / "bench_scale"
COLUMNS = ("preset", "path", "panorama", "source", "object triangles", "seconds", "time x1K",
           "peak memory GB", "memory x1K", "error ratio", "slowest stages (s)")


@dataclass(frozen=True)
class Case:
    """One row's input: a `width` x width/2 panorama, upsampled `factor` times from the pair
    `pair` (1: the pair's own render, which scores the edit; None: a photograph, unscored), the
    object `name` split into `split`^2, and what the row says the panorama is."""

    width: int
    split: int
    factor: int
    pair: dict[str, Path] | None
    folder: Path
    name: str
    source: str


#: A preset's name and the working width it solves at (None: the preset's own).
Preset = tuple[str, int | None]


@dataclass(frozen=True)
class Measured:
    """One run: exit status, wall seconds and peak resident GiB of its process, its output folder."""

    status: int
    seconds: float
    peak_gb: float
    out: Path


def _cases(args: argparse.Namespace) -> list[Case]:
    """The rows' inputs, built and cached: the sizes with k = 1, then the splits at --width."""
    rendered = {args.width, *_ints(args.truth_sizes)}
    cases = []
    # The --width row first: the ratios divide by it.
    sizes = sorted({args.width, *_ints(args.sizes)})
    wanted = [(w, 1) for w in sizes] + [(args.width, k) for k in _ints(args.splits) if k != 1]
    for width, split in wanted:
        source = width if width in rendered else args.width
        spec = scene_specs.get(args.scene).with_render(width=source, height=source // 2, samples=args.samples)
        factor = width // source
        folder = CACHE / spec.key() / f"x{factor}-k{split}"
        source_label = "render" if factor == 1 else f"upsampled x{factor}"
        case = Case(width, split, factor, render_pair(spec), folder, spec.remove, source_label)
        if not _built(folder):
            _setup(case)
        cases.append(case)
    return cases + [_room(room, args) for room in args.rooms.split(",") if room]


def _room(room: str, args: argparse.Namespace) -> Case:
    """A row of another room at --width: a scene spec rendered with Cycles (a window-lit one), or
    `interior`, Blender's hotel-room photograph (1024x512) with its room and armchair built from
    the committed click file (`real_photo_crops`)."""
    if room == "interior":
        if args.width != 1024:
            sys.exit("the interior photograph is 1024x512: run the interior row at --width 1024")
        case = Case(args.width, 1, 1, None, CACHE / "interior", "Armchair", "interior.exr photograph")
    else:
        spec = scene_specs.get(room).with_render(width=args.width, height=args.width // 2, samples=args.samples)
        case = Case(args.width, 1, 1, render_pair(spec), CACHE / spec.key() / "x1-k1", spec.remove,
                    f"{room} render")
    if not _built(case.folder):
        _setup(case)
    return case


def _built(folder: Path) -> bool:
    """Whether the case in `folder` is built and its panorama is where its files say (a case
    copied from another checkout, or built before paths were kept relative, is built again)."""
    if not (folder / "case.json").exists():
        return False
    hdri = json.loads((folder / "case.json").read_text()).get("hdri")
    return hdri is not None and (folder / hdri).is_file()


def _setup(case: Case) -> None:
    print(f"building the {case.width}x{case.width // 2}, k={case.split} input in {case.folder}", file=sys.stderr)
    case.folder.mkdir(parents=True, exist_ok=True)
    scene = ["--photo", "hotel"] if case.pair is None else ["--blend", str(case.pair["blend"])]
    command = [sys.executable, __file__, "--setup", str(case.folder), *scene,
               "--object", case.name, "--factor", str(case.factor), "--split", str(case.split)]
    proc = subprocess.run(command, cwd=REPO, capture_output=True, text=True)
    if proc.returncode:
        sys.exit(f"building {case.folder} failed:\n{(proc.stdout + proc.stderr)[-3000:]}")


def _build(args: argparse.Namespace) -> None:
    """In a bpy subprocess: the pair's .blend with its world image upsampled and the object's
    mesh split, saved as scene.blend with the geometry as geometry.npz; case.json comes last."""
    import bpy

    from addon.blender import reader
    from addon.blender.blend_file import open_blend
    from scenes.images import write_exr

    if args.photo is not None:
        from real_photo_crops import _scenes, build

        args.blend, _ = build(_scenes()[args.photo], args.setup / "photo")
    open_blend(str(args.blend))
    scene = bpy.context.scene
    if args.factor > 1:
        image = reader.environment_texture(scene).image
        world = read_exr(bpy.path.abspath(image.filepath))
        path = args.setup / "world.exr"
        write_exr(path, np.repeat(np.repeat(world, args.factor, axis=0), args.factor, axis=1))
        image.filepath = str(path)
    if args.split > 1:
        _split_mesh(bpy.data.objects[args.object], args.split)
    bpy.ops.wm.save_as_mainfile(filepath=str(args.setup / "scene.blend"))
    # Paths relative to the case, so that the cache stays valid wherever the checkout is.
    bpy.ops.file.make_paths_relative()
    bpy.ops.wm.save_mainfile()
    data = reader.read_scene(scene, defer_file=True)
    hdri = os.path.relpath(data.hdri_path, args.setup)
    np.savez(args.setup / "geometry.npz", rotation=data.rotation, center=data.center, triangles=data.triangles,
             tri_object=data.tri_object, object_names=np.array(data.object_names), hdri_path=hdri)
    triangles = int((data.tri_object == data.object_index(args.object)).sum())
    (args.setup / "case.json").write_text(json.dumps({"triangles": triangles, "hdri": hdri}))


def _split_mesh(obj, k: int) -> None:
    """Give `obj` a mesh of its triangles each split into k^2 (the same surface, unwelded)."""
    import bpy

    from addon.geometry.patches import split_triangles

    mesh = obj.data
    mesh.calc_loop_triangles()
    coords = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", coords)
    corners = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", corners)
    fine = split_triangles(coords.reshape(-1, 3)[corners.reshape(-1, 3)].astype(np.float64), k).reshape(-1, 3)
    split = bpy.data.meshes.new(f"{mesh.name}.split{k}")
    split.vertices.add(len(fine))
    split.vertices.foreach_set("co", fine.astype(np.float32).ravel())
    split.loops.add(len(fine))
    split.loops.foreach_set("vertex_index", np.arange(len(fine), dtype=np.int32))
    split.polygons.add(len(fine) // 3)
    split.polygons.foreach_set("loop_start", np.arange(0, len(fine), 3, dtype=np.int32))
    split.update(calc_edges=True)
    for material in mesh.materials:
        split.materials.append(material)
    obj.data = split


def _engine(args: argparse.Namespace) -> None:
    """In a subprocess without bpy: one removal of the case in `args.engine_child`; writes its
    report (and the difference, for a scored row) into `args.out`."""
    from addon.pipeline import remove_object
    from addon.run.job import loaded
    from addon.scene import SceneData

    data = np.load(args.engine_child / "geometry.npz")
    scene = loaded(SceneData(hdri=None, rotation=data["rotation"], center=data["center"],
                             triangles=data["triangles"], tri_object=data["tri_object"],
                             object_names=[str(n) for n in data["object_names"]],
                             hdri_path=str(args.engine_child / str(data["hdri_path"]))))
    overrides = {} if args.working_width is None else {"working_width": args.working_width}
    result = remove_object(scene, args.object, quality=args.quality, **overrides)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "report.json").write_text(json.dumps(result.report))
    if args.difference:
        np.save(args.out / "difference.npy", result.difference)


def _measure(command: list[str], out: Path) -> Measured:
    """Run `command` to its end with its output in out/log.txt."""
    out.mkdir(parents=True)
    started = time.perf_counter()
    with open(out / "log.txt", "w") as log:
        proc = subprocess.Popen(command, cwd=REPO, stdout=log, stderr=subprocess.STDOUT)
        # wait4 returns this child's own rusage; RUSAGE_CHILDREN would hold the largest so far.
        _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return Measured(proc.returncode, time.perf_counter() - started, usage.ru_maxrss / 2**20, out / "result")


def _fastest(case: Case, preset: Preset, engine: bool, folder: Path, repeat: int) -> Measured:
    """The fastest of `repeat` runs (a failed one at once): a run of a shared machine is only
    ever slowed by what else it does, so the least time is the run's own."""
    runs = []
    for attempt in range(repeat):
        runs.append(_run(case, preset, engine, folder / f"run{attempt}"))
        if runs[-1].status:
            return runs[-1]
    return min(runs, key=lambda run: run.seconds)


def _run(case: Case, preset: Preset, engine: bool, folder: Path) -> Measured:
    quality, working_width = preset
    out = folder / f"{quality}-{working_width}-{case.width}-k{case.split}-{case.folder.name}-{case.name}"
    if engine:
        command = [sys.executable, __file__, "--engine-child", str(case.folder), "--object", case.name,
                   "--quality", quality, "--out", str(out / "result")]
        command += ["--difference"] if case.pair is not None and case.factor == 1 else []
    else:
        command = [sys.executable, "-m", "addon.cli", "remove", str(case.folder / "scene.blend"), "--object", case.name,
                   "--out", str(out / "result"), "--quality", quality]
    command += [] if working_width is None else ["--working-width", str(working_width)]
    return _measure(command, out)


def _error(case: Case, run: Measured, engine: bool) -> str:
    """The lighting error ratio against the truth of a rendered size, else ''."""
    if case.pair is None or case.factor != 1:
        return ""
    inp, truth, mask = read_exr(case.pair["input"]), read_exr(case.pair["truth"]), np.load(case.pair["mask"])
    edited = inp + np.load(run.out / "difference.npy") if engine else read_exr(run.out / "edited.exr")
    return f"{metrics.lighting_error_ratio(inp, edited, truth, mask):.3f}"


def _cells(preset: Preset, engine: bool, case: Case, run: Measured, base: Measured) -> list[str]:
    quality, working_width = preset
    panorama = f"{case.width}x{case.width // 2}"
    label = quality if working_width is None else f"{quality}, solved at {working_width}"
    head = [label, "engine" if engine else "cli", panorama, case.source]
    triangles = json.loads((case.folder / "case.json").read_text())["triangles"]
    if run.status:
        tail = (run.out.parent / "log.txt").read_text().strip().splitlines() or ["no output"]
        return [*head, str(triangles), f"failed ({run.status}): {tail[-1]}", "", "", "", "", ""]
    stages = _stages(run, engine)
    slowest = sorted(((v, k) for k, v in stages.items() if k not in ("total", "read_scene")), reverse=True)[:3]
    ok = not base.status
    return [*head, str(triangles), f"{run.seconds:.1f}", f"{run.seconds / base.seconds:.2f}" if ok else "",
            f"{run.peak_gb:.2f}", f"{run.peak_gb / base.peak_gb:.2f}" if ok else "", _error(case, run, engine),
            ", ".join(f"{k} {v:.1f}" for v, k in slowest)]


def _stages(run: Measured, engine: bool) -> dict[str, float]:
    """The run's report's seconds per stage, in the order they ran; on the command line with the
    writing of the results, which the report's own seconds end before: the command's total
    ("removed ... in T s") less the report's."""
    stages = json.loads((run.out / "report.json").read_text())["seconds"]
    said = None if engine else re.search(r" in ([0-9.]+) s; wrote", (run.out.parent / "log.txt").read_text())
    if said:
        stages["write"] = float(said.group(1)) - stages["total"]
    return stages


def _profile(label: str, case: Case, run: Measured, engine: bool) -> str:
    """One line: every stage of the run of `case`, and what the process spent besides."""
    if run.status:
        return f"{label} at {case.width}x{case.width // 2} failed."
    stages = _stages(run, engine)
    # The report's total runs from the scene's reading to the end of the removal; some stages
    # run side by side (relit_noise beside hidden_light), so their seconds add up to more.
    counted = stages["total"] + stages.get("write", 0.0)
    # The scene is read first, though the command line adds its seconds to the report last.
    parts = [f"{k} {stages[k]:.1f}" for k in sorted(stages, key=lambda k: k != "read_scene") if k != "total"]
    return (f"Every stage of {label} at {case.width}x{case.width // 2} (s): {', '.join(parts)}; the process's "
            f"start and the rest {run.seconds - counted:.1f}.")


def _floor(case: Case) -> str:
    """What one pass over the pixels of `case`'s panorama costs here, in this process: reading
    its EXR, one numpy pass (the edited panorama's sum of two images) and writing it as the
    command line writes its results (the engine's reader and writer, with memory handed out as
    a run has it: `run_memory`); and the sum into a new array under numpy's default huge-page
    advice."""
    hdri = json.loads((case.folder / "case.json").read_text())["hdri"]
    with run_memory():
        started = time.perf_counter()
        image = exr.read_exr(case.folder / hdri)
        read = time.perf_counter() - started
        started = time.perf_counter()
        out = image + image
        add = time.perf_counter() - started
        started = time.perf_counter()
        np.add(image, image, out=out)
        again = time.perf_counter() - started
        with tempfile.TemporaryDirectory() as folder:
            started = time.perf_counter()
            exr.write_exr(Path(folder) / "pass.exr", out)
            written = time.perf_counter() - started
    del out
    started = time.perf_counter()
    advised = image + image
    add_advised = time.perf_counter() - started
    del advised
    pixels = image.shape[0] * image.shape[1]
    return (f"one pass over the {image.shape[1]}x{image.shape[0]} panorama ({pixels / 1e6:.1f} M float32 RGB pixels) "
            f"here, with memory as a run has it: reading its EXR {read:.2f} s; a numpy sum of two such images "
            f"{add:.2f} s into a new array, {again:.2f} s into the same one again; writing one EXR {written:.2f} s. "
            f"The same sum into a new array under numpy's default huge-page advice: {add_advised:.2f} s")


def _ints(text: str) -> list[int]:
    return [int(x) for x in text.split(",") if x]


def main() -> None:
    ap = arguments(__doc__)
    ap.set_defaults(samples=8)
    ap.add_argument("--sizes", default="1024,2048,4096,8192,16384",
                    help="panorama widths, multiples of --width (larger ones are upsampled)")
    ap.add_argument("--splits", default="1,9,29,64", help="k: each of the object's triangles split into k^2")
    ap.add_argument("--quality", default="balanced", help="presets, comma-separated")
    ap.add_argument("--truth-sizes", default="2048", help="widths also rendered with Cycles, so scored")
    ap.add_argument("--working-widths", default="", help="working widths, comma-separated (default: the preset's)")
    ap.add_argument("--engine", action="store_true", help="the engine alone instead of the command line")
    ap.add_argument("--repeat", type=int, default=1, help="runs of each row, the fastest kept")
    ap.add_argument("--rooms", default="hotel_chair,interior",
                    help="rows of other rooms at --width: scene specs (hotel_chair: lit through a window with a "
                         "sun patch) and interior (Blender's hotel photograph); '' for none")
    ap.add_argument("--setup", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--blend", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--photo", help=argparse.SUPPRESS)
    ap.add_argument("--working-width", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--factor", type=int, default=1, help=argparse.SUPPRESS)
    ap.add_argument("--split", type=int, default=1, help=argparse.SUPPRESS)
    ap.add_argument("--engine-child", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--object", help=argparse.SUPPRESS)
    ap.add_argument("--out", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--difference", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.setup is not None:
        _build(args)
        return
    if args.engine_child is not None:
        _engine(args)
        return
    if any(w % args.width for w in _ints(args.sizes)):
        ap.error("--sizes must be multiples of --width")
    cases = _cases(args)
    pair = cases[0].pair
    floor = metrics.noise_floor(read_exr(pair["input"]), read_exr(pair["truth"]), np.load(pair["mask"]))
    rows, profiles = [], []
    widest = max(cases, key=lambda c: (c.width, -c.split, c.pair is not None))
    with tempfile.TemporaryDirectory() as folder:
        widths = _ints(args.working_widths) or [None]
        for preset in [(quality, w) for quality in args.quality.split(",") for w in widths]:
            base = _fastest(cases[0], preset, args.engine, Path(folder), args.repeat)
            for case in cases:
                run = base if case is cases[0] else _fastest(case, preset, args.engine, Path(folder), args.repeat)
                rows.append(_cells(preset, args.engine, case, run, base))
                print(" | ".join(rows[-1]), file=sys.stderr, flush=True)
                if case is widest:
                    profiles.append(_profile(rows[-1][0], case, run, args.engine))
    table = Table(COLUMNS, title=f"scene {args.scene} rendered {args.width}x{args.width // 2} @ {args.samples} spp; "
                                 f"noise floor {floor:.3f}; seconds: process wall time"
                                 f"{f', the fastest of {args.repeat} runs' if args.repeat > 1 else ''}; peak memory: "
                                 "its maximum resident set")
    for row in rows:
        table.row(*row)
    write(table, notes=[*profiles, f"The floor to compare against: {_floor(widest)}."])


if __name__ == "__main__":
    main()
