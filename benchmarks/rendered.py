"""The rendered scene a benchmark runs on: command-line options and the opened .blend."""
from __future__ import annotations

import argparse
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from scenes import spec as scene_specs
from scenes.images import read_exr
from scenes.render import render_pair


def arguments(description: str) -> argparse.ArgumentParser:
    """A parser with --scene, --width (height = width / 2) and --samples of the Cycles render."""
    ap = argparse.ArgumentParser(description=description)
    ap.add_argument("--scene", default="basic_box")
    ap.add_argument("--width", type=int, default=1024)
    ap.add_argument("--samples", type=int, default=16)
    return ap


def open_scene(args: argparse.Namespace) -> tuple[scene_specs.SceneSpec, dict[str, Path]]:
    """Render the pair unless cached, open its .blend in Blender; (spec, paths of the pair)."""
    spec = scene_specs.get(args.scene).with_render(width=args.width, height=args.width // 2, samples=args.samples)
    paths = render_pair(spec)
    from addon.blender.blend_file import open_blend  # bpy only after rendering, which runs in a subprocess

    open_blend(str(paths["blend"]))
    return spec, paths


#: The ground-truth scenes with tiled and planked floors the fill and relighting benchmarks run on.
FLOOR_SCENES = "basic_box,wall_contact,far_dark_box,tile_stool,stool,warm_cylinder,demo,oak_chair,walnut_crate,far_pouf"


def scene_list_arguments(description: str, scenes: str, *, width: int = 1024, samples: int = 16) -> argparse.Namespace:
    """Parsed --scenes (comma-separated, default `scenes`), --width (height = width / 2) and
    --samples (the demo gets at least 32)."""
    ap = argparse.ArgumentParser(description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", default=scenes)
    ap.add_argument("--width", type=int, default=width)
    ap.add_argument("--samples", type=int, default=samples, help="Cycles samples (the demo gets at least 32)")
    return ap.parse_args()


@dataclass(frozen=True)
class GroundTruth:
    """A rendered pair: its spec, the panorama with the object and without it, the object's
    mask, and the scene as the add-on reads it from the opened .blend."""

    spec: scene_specs.SceneSpec
    input: np.ndarray
    truth: np.ndarray
    mask: np.ndarray
    scene: Any


def ground_truths(args: argparse.Namespace) -> Iterator[GroundTruth]:
    """Each of `args.scenes` rendered unless cached and opened in Blender, in turn."""
    import bpy

    from addon.blender import reader

    for name in args.scenes.split(","):
        spec = scene_specs.get(name).with_render(width=args.width, height=args.width // 2,
                                                 samples=max(args.samples, 32) if name == "demo" else args.samples)
        paths = render_pair(spec)
        bpy.ops.wm.open_mainfile(filepath=str(paths["blend"]))
        yield GroundTruth(spec, read_exr(paths["input"]), read_exr(paths["truth"]), np.load(paths["mask"]),
                          reader.read_scene(bpy.context.scene))


def second_render_structure(gt: GroundTruth, mask: np.ndarray | None = None) -> float:
    """The structure (`scenes.metrics.structure_correlation`) over `mask` (default: the object's
    pixels) of the truth rendered again with another seed: what the render's noise alone leaves
    of a perfect fill's score, the ceiling a fill's structure is read against (rendered unless
    cached)."""
    from scenes import metrics

    again = read_exr(render_pair(gt.spec.with_render(seed=gt.spec.render.seed + 1))["truth"])
    return metrics.structure_correlation(again, gt.truth, gt.mask if mask is None else mask)
