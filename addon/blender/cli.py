"""The command line: remove or move an object in a scene's panorama without Blender's interface.

    python -m addon.cli remove SCENE.blend --object NAME --out DIR [options]
    python -m addon.cli relocate SCENE.blend --object NAME --yaw DEG --distance-scale S --out DIR [options]
    python -m addon.cli align SCENE.blend --object NAME --out DIR [--save COPY.blend] [options]
    blender -b SCENE.blend -c dimred remove|relocate|align ... (the same arguments)
    python -m addon.cli batch JOBS --out DIR ...  and  inspect SCENE.blend ... (`batch_cli`)
    python -m addon.cli room [SCENE.blend] --clicks CLICKS.json --save OUT.blend --out DIR (`room_cli`)

Both run `run_cli`; inside Blender the .blend is already open, so SCENE.blend is optional.
Bad input gets one line `dimred: error: ...` on stderr, exit code 2, and nothing on disk.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

from .. import memory
from ..callbacks import RunCallbacks
from ..errors import DimredError
from ..quality import DEFAULT_QUALITY, DESCRIPTIONS, MIN_WORKING_WIDTH, PRESETS, working_width_problem
from ..run_memory import run_memory
from . import batch_cli, room_cli

if TYPE_CHECKING:
    from ..removal import RemovalResult
    from ..scene import SceneData

PROG = "dimred"
#: Exit status for bad input (the same as argparse's usage errors).
EXIT_BAD_INPUT = 2

_DESCRIPTION = """\
Remove a real object from the HDR panorama (light probe) that is the world's Environment
Texture: its shadow, the light it reflected, and the object itself, filled with texture
synthesised from the surface around it. Writes into the output folder:

  difference.exr   what to add to the panorama (RGB float32, the panorama's size)
  edited.exr       the panorama plus the difference
  report.json      seconds per stage, skipped stages, warnings, guards, error estimates,
                   the segmentation and (with --align) the alignment
  diagnostics.png  the proxy's silhouette against the object's outline in the photograph
                   (cyan: the proxy's outline, yellow: the photograph's; red: object the proxy
                   misses, blue: proxy over no object)
  hidden_mask.png  only when the region the object hid could not be filled (white = hidden)

Files are written only when the whole run succeeds."""

_QUALITY_HELP = f"accuracy preset (default: {DEFAULT_QUALITY}; see the presets below)"

_WORKING_WIDTH_HELP = (
    f"solve the light on a copy of the panorama at most this wide (even, at least {MIN_WORKING_WIDTH}; default: "
    + ", ".join(f"{name} {params.working_width}" for name, params in PRESETS.items())
    + "); the full-size panorama takes the light from there and is filled at its own size: wider resolves "
    "finer shadows for more time and memory")

_PRESET_LINES = "\n".join(f"  {name:<10} {description}" for name, description in DESCRIPTIONS.items())

_EPILOG = f"""\
quality presets (--quality):
{_PRESET_LINES}

The probe centre (where the panorama was taken) is --center if given, else the scene's
Diminished Reality setting or custom property probe_center, else an object named
ProbeCenter, else the world origin.

examples:
  python -m addon.cli remove room.blend --object Box --out out/
  blender -b room.blend -c dimred remove --object Box --plane Floor --quality final --out out/
  python -m addon.cli remove room.blend --object Box --align --mask cable.png --out out/
  python -m addon.cli relocate room.blend --object Box --yaw 40 --distance-scale 1.3 --out out/
  python -m addon.cli align room.blend --object Box --out out/ --save room_aligned.blend"""

_ALIGN_DESCRIPTION = """Align to Photo: fit the pose of a proxy placed by eye to the object's outline in the panorama,
segmented around the proxy's silhouette: a shift along its support, a turn about the vertical
and a uniform scale about its bottom centre (with --fit-height: the support's height instead
of the scale, for a proxy whose size is known). Writes into the output folder:

  report.json      "alignment": the correction (shift_cm, turn_deg, scale_percent), its world
                   matrix C (the corrected matrix_world is C @ matrix_world), the outline's rms
                   distance before and after (pixels); "segmentation": what the photograph showed
  diagnostics.png  the corrected proxy's silhouette against the outline

With --save, a copy of the .blend with the corrected object (the .blend itself is not changed).
A fit that does not converge to a plausible pose leaves the proxy where it was, says so and
exits with status 1 (report.json is written, no copy is saved)."""

_RELOCATE_DESCRIPTION = """\
Move a real object elsewhere in the HDR panorama under the fixed-view constraint: the
panorama shows it from one side only, so it may only turn about the vertical axis through the
probe centre (its position and its orientation by the same angle, --yaw) and change its
horizontal distance from that axis (--distance-scale), standing on the surface it stands on.
It is removed at the old place (shadow, reflected light, the floor behind it synthesised) and
inserted at the new one (its appearance from the panorama relit there, hiding what is behind
it, its new shadow and reflected light). A move off its support surface, through a wall or
another object, or with a distance factor <= 0 is refused. Writes the same files as remove:

  difference.exr   what to add to the panorama (RGB float32, the panorama's size)
  edited.exr       the panorama plus the difference
  report.json      as for remove, plus "relocation": the move, its world matrix, the
                   change of view elevation (degrees) and the insertion's convergence"""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of `python -m addon.cli`: the .blend is a required argument."""
    return run_cli(sys.argv[1:] if argv is None else argv, blend_already_loaded=False)


def blender_command(argv: Sequence[str]) -> int:
    """Entry point of `blender -b SCENE.blend -c dimred ...` (bpy.utils.register_cli_command
    passes the arguments after the command id)."""
    return run_cli(argv, blend_already_loaded=True)


def run_cli(argv: Sequence[str], *, blend_already_loaded: bool) -> int:
    """Parse `argv` and run the subcommand; returns the exit status."""
    parser = build_parser(blend_already_loaded=blend_already_loaded)
    try:
        args = parser.parse_args(list(argv))
    except SystemExit as stop:
        # argparse exits after --help or a usage error; both callers want a status returned.
        return stop.code if isinstance(stop.code, int) else EXIT_BAD_INPUT
    try:
        # Reading and writing the panorama allocate as much as the removal does.
        with run_memory():
            return args.run(args)
    except DimredError as error:
        # The contract is one line, whatever the message holds.
        print(f"{PROG}: error: {' '.join(str(error).split())}", file=sys.stderr, flush=True)
        return EXIT_BAD_INPUT


def build_parser(*, blend_already_loaded: bool) -> argparse.ArgumentParser:
    """The argument parser; inside Blender SCENE.blend is optional (the open file is used)."""
    parser = argparse.ArgumentParser(
        prog="blender -b SCENE.blend -c dimred" if blend_already_loaded else "python -m addon.cli",
        description=_DESCRIPTION,
        epilog=_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    commands = parser.add_subparsers(title="commands", dest="command", required=True, metavar="COMMAND")
    remove = _command(commands, "remove", "remove an object from the panorama", _DESCRIPTION)
    _scene_arguments(remove, blend_already_loaded,
                     "the mesh object to remove (repeatable: several are removed in this order, each from the "
                     "panorama the ones before left, as in the add-on's panel)")
    remove.set_defaults(run=_remove)
    relocate = _command(commands, "relocate", "move an object elsewhere in the panorama (fixed-view constraint)",
                        _RELOCATE_DESCRIPTION)
    _scene_arguments(relocate, blend_already_loaded, "the mesh object to move")
    relocate.add_argument("--yaw", type=float, default=0.0, metavar="DEG",
                          help="degrees to turn the object about the vertical axis through the probe centre "
                               "(counter-clockwise seen from above; its orientation turns by the same angle)")
    relocate.add_argument("--distance-scale", type=float, default=1.0, metavar="S",
                          help="factor on the object's horizontal distance from that axis (> 0; default 1)")
    relocate.set_defaults(run=_relocate)
    align = _command(commands, "align", "fit the proxy's pose to the object's outline in the panorama (Align to Photo)",
                     _ALIGN_DESCRIPTION)
    _scene_arguments(align, blend_already_loaded, "the mesh object to align", removal=False)
    align.add_argument("--save", metavar="COPY.blend", help="write a copy of the .blend with the corrected object")
    align.set_defaults(run=_align)
    batch_cli.add_commands(commands, formatter=argparse.RawDescriptionHelpFormatter,
                           inside_blender=blend_already_loaded)
    room_cli.add_command(commands, formatter=argparse.RawDescriptionHelpFormatter, inside_blender=blend_already_loaded)
    return parser


def _command(commands: argparse._SubParsersAction, name: str, summary: str, description: str
             ) -> argparse.ArgumentParser:
    return commands.add_parser(name, help=summary, description=description, epilog=_EPILOG,
                               formatter_class=argparse.RawDescriptionHelpFormatter)


def _scene_arguments(parser: argparse.ArgumentParser, blend_already_loaded: bool, object_help: str, *,
                     removal: bool = True) -> None:
    blend_help = "the scene (.blend) to read"
    if blend_already_loaded:
        parser.add_argument("blend", nargs="?", metavar="SCENE.blend", help=blend_help + " (default: the open file)")
    else:
        parser.add_argument("blend", metavar="SCENE.blend", help=blend_help)
    parser.add_argument("--object", dest="objects", action="append", required=True, metavar="NAME", help=object_help)
    parser.add_argument("--fit-height", action="store_true",
                        help="align: fit the support's height instead of the object's scale (a proxy of known size)")
    if removal:
        parser.add_argument("--align", action="store_true",
                            help="first fit the proxy's pose to the object's outline in the panorama (Align to Photo)")
        parser.add_argument("--mask", metavar="FILE",
                            help="image the panorama's size (or an integer fraction of it): white adds to the region "
                                 "filled, black takes away, grey or transparent leaves it")
    parser.add_argument(
        "--plane",
        action="append",
        default=[],
        metavar="NAME",
        help="a mesh surface to edit (repeatable); without it the surfaces the removal reveals or relights are found",
    )
    parser.add_argument("--out", required=True, metavar="DIR", help="output folder (created if needed)")
    parser.add_argument("--quality", choices=tuple(DESCRIPTIONS), default=DEFAULT_QUALITY, help=_QUALITY_HELP)
    if removal:
        parser.add_argument("--working-width", type=_working_width, metavar="PX", help=_WORKING_WIDTH_HELP)
    parser.add_argument(
        "--center",
        nargs=3,
        type=float,
        metavar=("X", "Y", "Z"),
        help="probe centre in world space, overriding the scene's",
    )
    parser.add_argument("--verbose", action="store_true", help="print progress and notes on stderr")


def _working_width(text: str) -> int:
    try:
        width = int(text)
    except ValueError:
        width = None
    problem = working_width_problem(width)
    if problem:
        raise argparse.ArgumentTypeError(f"{problem}, not {text!r}")
    return width


def _overrides(args: argparse.Namespace) -> dict[str, int]:
    """The preset's parameters the command line sets."""
    return {} if getattr(args, "working_width", None) is None else {"working_width": args.working_width}


def _remove(args: argparse.Namespace) -> int:
    from .. import pipeline
    from ..composition import remove_in_order

    def compute(scene: SceneData, **options) -> RemovalResult:
        return remove_in_order(scene, args.objects, lambda step, name: pipeline.remove_object(
            step, name, align=args.align, fit_height=args.fit_height, **options))

    return _run(args, "removed", compute)


def _relocate(args: argparse.Namespace) -> int:
    from .. import pipeline
    from ..relocation.fixedview import Move, check_move

    move = Move(args.yaw, args.distance_scale)
    # Before the scene is read: a request no placement satisfies needs no .blend.
    check_move(move)
    return _run(args, "moved", lambda scene, **options: pipeline.relocate_object(
        scene, _single(args), move, align=args.align, fit_height=args.fit_height, **options))


def _single(args: argparse.Namespace) -> str:
    if len(args.objects) != 1:
        raise DimredError(f"{args.command} takes one --object, not {len(args.objects)}")
    return args.objects[0]


def _align(args: argparse.Namespace) -> int:
    import bpy
    from mathutils import Matrix

    from .. import pipeline
    from ..io.exr import write_png
    from ..io.outputs import json_writer, write_files
    from ..segmentation.diagnostics import picture_of

    started = time.perf_counter()
    out = _output_folder(args.out)
    scene_data = _read(args)
    save = os.path.abspath(args.save) if args.save else None
    if save and os.path.abspath(bpy.data.filepath) == save:
        raise DimredError("--save must name a copy, not the .blend that is open")
    name = _single(args)
    alignment = pipeline.align_to_photo(scene_data, name, quality=args.quality, fit_height=args.fit_height)
    moved = alignment.moved(scene_data, scene_data.object_index(name))
    seen = pipeline.photographed_object(moved, name, quality=args.quality)
    report = {"alignment": alignment.summary(), "segmentation": seen.summary() if seen else None,
              "seconds": {"alignment": round(alignment.seconds, 4),
                          "total": round(time.perf_counter() - started, 4)}}
    picture = None if seen is None else picture_of(seen)
    write_files(out, {"report.json": json_writer(report)}
                 | ({} if picture is None else {"diagnostics.png": lambda path: write_png(path, picture)}),
                 stale=("diagnostics.png",))
    if not alignment.applied and not alignment.fits:
        print(f"{PROG}: {alignment.message}", file=sys.stderr, flush=True)
        return 1
    if save:
        obj = bpy.context.scene.objects[name]
        obj.matrix_world = Matrix(alignment.matrix.tolist()) @ obj.matrix_world
        try:
            bpy.ops.wm.save_as_mainfile(filepath=save, copy=True)
        except RuntimeError as error:
            raise DimredError(f"cannot save {save}: {str(error).strip()}") from None
    print(f"{PROG}: {alignment.message}; wrote {out}" + (f" and {save}" if save else ""), flush=True)
    return 0


def _run(args: argparse.Namespace, done: str, compute: Callable[..., RemovalResult]) -> int:
    from ..io.outputs import write_outputs

    started = time.perf_counter()
    out = _output_folder(args.out)
    scene_data = _read(args)
    mask = None
    if args.mask:
        from .mask_reader import read_mask_file

        mask = read_mask_file(args.mask, (scene_data.hdri.shape[1], scene_data.hdri.shape[0]))
    loaded = time.perf_counter()
    result = compute(
        scene_data,
        planes=list(args.plane),
        quality=args.quality,
        mask=mask,
        callbacks=RunCallbacks(progress=_print_progress if args.verbose else None),
        **_overrides(args),
    )
    report = dict(result.report)
    seconds = dict(report.get("seconds", {}))
    seconds["read_scene"] = round(loaded - started, 4)
    seconds["total"] = round(time.perf_counter() - started, 4)
    report["seconds"] = seconds
    write_outputs(out, result, report)
    total = time.perf_counter() - started
    print(f"{PROG}: {done} {', '.join(repr(n) for n in args.objects)} in {total:.1f} s; wrote {out}", flush=True)
    for warning in report.get("warnings", []):
        print(f"{PROG}: warning: {warning}", file=sys.stderr)
    return 0


def _output_folder(path: str) -> str:
    out = os.path.abspath(path)
    if os.path.exists(out) and not os.path.isdir(out):
        raise DimredError(f"--out {out} is a file, not a folder")
    return out


def _read(args: argparse.Namespace) -> SceneData:
    """The scene of the command's .blend (opened unless inside Blender), its object checked,
    refused before its pixels are read when the run cannot fit in memory."""
    import bpy

    from . import reader
    from .blend_file import open_blend

    if args.blend is not None:
        open_blend(args.blend)
    elif not bpy.data.filepath:
        raise DimredError("no .blend file is open: pass SCENE.blend")
    scene = bpy.context.scene
    if args.command != "remove":
        _single(args)
    if len(set(args.objects)) != len(args.objects):
        raise DimredError("an --object is named twice")
    for name in args.objects:
        reader.check_object(scene, name)
    for plane in args.plane:
        if plane in args.objects:
            raise DimredError(f"'{plane}' is the object itself; it cannot also be a --plane")
        reader.check_object(scene, plane, purpose="used as a --plane")
    # Before the pixels are read: a run that cannot fit is refused now, not killed halfway.
    width, height = reader.panorama_size(scene)
    memory.check_fits(width, height, quality=args.quality, **_overrides(args))
    scene_data = reader.read_scene(scene, center=args.center)
    if args.verbose:
        for note in scene_data.notes:
            print(f"{PROG}: note: {note}", file=sys.stderr)
    return scene_data


def _print_progress(stage: str, fraction: float) -> None:
    print(f"{PROG}: {100.0 * fraction:5.1f}% {stage}", file=sys.stderr, flush=True)
