"""The rendered scene a benchmark runs on: command-line options and the opened .blend."""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from scenes import spec as scene_specs
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
    from addon.blender.cli import open_blend  # bpy only after rendering, which runs in a subprocess

    open_blend(str(paths["blend"]))
    return spec, paths
