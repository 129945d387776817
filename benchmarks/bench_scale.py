"""Seconds and peak memory of a removal per panorama size and per object triangle count.

    .venv/bin/python benchmarks/bench_scale.py [--sizes 1024,2048,4096] [--splits 1,9,29,64]
                                               [--quality balanced] [--scene basic_box]

The scene is rendered at 1024x512 (cached under .cache/groundtruth). A larger panorama is that
render upsampled (each pixel repeated), which is fine for timing; the error column is against
the Cycles truth where one exists (the render's own size). The triangle counts come from
splitting each of the removed box's 12 triangles into k^2 (the same shape, so the same truth):
k = 1, 9, 29, 64 give 12, 972, 10092 and 49152 triangles. Every run is its own process reading
the scene from a file (no bpy), so its peak resident memory (ru_maxrss) is the engine's alone.
Timings on a shared machine are noisy: compare the rows of one run.
"""
from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from rendered import arguments, open_scene
from scenes import metrics


def _save(scene, path: Path) -> None:
    np.savez(path, hdri=scene.hdri, rotation=scene.rotation, center=scene.center, triangles=scene.triangles,
             tri_object=scene.tri_object, object_names=np.array(scene.object_names))


def _load(path: Path):
    from addon.scene import SceneData

    data = np.load(path)
    return SceneData(hdri=data["hdri"], rotation=data["rotation"], center=data["center"],
                     triangles=data["triangles"], tri_object=data["tri_object"],
                     object_names=[str(n) for n in data["object_names"]])


def _split_object(scene, name: str, k: int):
    """The scene with each triangle of object `name` split into k^2 (same surface)."""
    from addon.geometry.patches import split_triangles

    index = scene.object_names.index(name)
    on = scene.tri_object == index
    fine = split_triangles(scene.triangles[on], k).reshape(-1, 3, 3)
    triangles = np.concatenate([scene.triangles[~on], fine])
    owners = np.concatenate([scene.tri_object[~on], np.full(len(fine), index, dtype=scene.tri_object.dtype)])
    return replace(scene, triangles=triangles, tri_object=owners)


def _child(args: argparse.Namespace) -> None:
    """One removal, in this process: prints its seconds and peak memory as JSON."""
    from addon.pipeline import remove_object

    scene = _load(args.child)
    if args.split > 1:
        scene = _split_object(scene, args.object, args.split)
    factor = args.width // scene.hdri.shape[1]
    if factor > 1:
        scene = replace(scene, hdri=np.repeat(np.repeat(scene.hdri, factor, axis=0), factor, axis=1))
    started = time.perf_counter()
    result = remove_object(scene, args.object, quality=args.quality)
    seconds = time.perf_counter() - started
    if args.difference:
        np.save(args.difference, result.difference)
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20  # KiB -> GiB
    triangles = int((scene.tri_object == scene.object_names.index(args.object)).sum())
    print(json.dumps({"seconds": seconds, "peak_gb": peak, "triangles": triangles, "stages": result.report["seconds"]}))


def _run(npz: Path, name: str, width: int, split: int, quality: str, difference: Path | None) -> dict:
    command = [sys.executable, __file__, "--child", str(npz), "--object", name, "--width", str(width),
               "--split", str(split), "--quality", quality]
    if difference is not None:
        command += ["--difference", str(difference)]
    proc = subprocess.run(command, capture_output=True, text=True)
    if proc.returncode:
        return {"error": (proc.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(proc.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = arguments(__doc__)
    ap.add_argument("--sizes", default="1024,2048,4096", help="panorama widths, multiples of the render's")
    ap.add_argument("--splits", default="1,9,29,64", help="k: each of the object's triangles split into k^2")
    ap.add_argument("--quality", default="balanced")
    ap.add_argument("--child", type=Path, help=argparse.SUPPRESS)
    ap.add_argument("--object", default="Box", help=argparse.SUPPRESS)
    ap.add_argument("--split", type=int, default=1, help=argparse.SUPPRESS)
    ap.add_argument("--difference", type=Path, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.child is not None:
        _child(args)
        return
    spec, paths = open_scene(args)

    import bpy

    from addon.blender import reader
    from scenes.images import read_exr

    inp, truth, mask = read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"])
    with tempfile.TemporaryDirectory() as folder:
        npz = Path(folder) / "scene.npz"
        _save(reader.read_scene(bpy.context.scene), npz)
        print(f"scene {args.scene} rendered {args.width}x{args.width // 2} @ {args.samples} spp, "
              f"{args.quality}; noise floor {metrics.noise_floor(inp, truth, mask):.3f}")
        print("| panorama | object triangles | seconds | peak memory GB | error ratio | slowest stages |")
        print("|---|---|---|---|---|---|")
        cases = [(w, 1) for w in map(int, args.sizes.split(","))]
        cases += [(args.width, k) for k in map(int, args.splits.split(",")) if k != 1]
        for width, split in cases:
            difference = Path(folder) / "difference.npy" if width == args.width else None
            row = _run(npz, spec.remove, width, split, args.quality, difference)
            if "error" in row:
                print(f"| {width}x{width // 2} | k={split} | failed: {row['error']} | | | |", flush=True)
                continue
            error = ""
            if difference is not None:
                edited = inp + np.load(difference)
                error = f"{metrics.lighting_error_ratio(inp, edited, truth, mask):.3f}"
            stages = sorted(((v, k) for k, v in row["stages"].items() if k != "total"), reverse=True)[:3]
            slowest = ", ".join(f"{k} {v:.1f}" for v, k in stages)
            print(f"| {width}x{width // 2} | {row['triangles']} | {row['seconds']:.1f} | {row['peak_gb']:.2f} | "
                  f"{error} | {slowest} |", flush=True)


if __name__ == "__main__":
    main()
