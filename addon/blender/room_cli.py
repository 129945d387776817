"""The command line's `room` command: Match Room from a click file, the batch route.

    python -m addon.cli room [SCENE.blend] --clicks CLICKS.json --save OUT.blend --out DIR [options]
    blender -b [SCENE.blend] -c dimred room --clicks CLICKS.json --save OUT.blend --out DIR [options]
"""
from __future__ import annotations

import argparse
import os

import numpy as np

from ..errors import DimredError

_DESCRIPTION = """\
Match Room: build the room's Floor, Walls and Ceiling from the floor corners clicked in the
panorama (a click file, JSON; see below), set the probe centre where the camera was (the
ProbeCenter Empty), and save the scene as OUT.blend (SCENE.blend itself is not changed; without
it an empty scene, whose world shows --panorama). Writes into the output folder:

  room.json             the room (corners, heights, wall lengths, the Manhattan turn), each
                        corner's and floor edge's reprojection error (pixels), and how far each
                        reprojected edge lies from the panorama's edges (pixels at 1024 wide)
  room_diagnostics.png  the panorama with every edge of the room drawn over it (green floor,
                        magenta ceiling, cyan corners; the clicks in yellow)

The click file's objects, and with --object-at X Y the object clicked there, get proxies (Object
from Photo), marked for removal (the last one as the target), "objects" in room.json: from one
click a box (width, depth, height and turn fitted to the object's outline), or a box stepped in
two heights where the outline shows one part higher; from a footprint (the contact points with the
floor, in order round it) a prism over it, its height fitted to the outline.

A click file: {"width": W, "height": H, "floor": [[x, y], ...], "ceiling": [x, y],
"camera_height": 1.6 | "known_length": {"kind": "wall", "edge": 0, "metres": 3.2} or
{"kind": "vertical" | "floor", "from": [x, y], "to": [x, y], "metres": 2.0}, "manhattan": true,
"objects": [{"name": "Armchair", "click": [x, y]} | {"name": "Table", "footprint": [[x, y], ...]}]}.
Pixel coordinates are (column, row) on a W x H panorama, row 0 at the top, whole numbers at pixel
centres; the floor corners in order round the room. Nothing is written when a click is bad."""


def add_command(commands: argparse._SubParsersAction, *, formatter: type[argparse.HelpFormatter],
                inside_blender: bool) -> None:
    room = commands.add_parser("room", help="build Floor, Walls and Ceiling from clicks in the panorama (Match Room)",
                               description=_DESCRIPTION, formatter_class=formatter)
    room.add_argument("blend", nargs="?", metavar="SCENE.blend",
                      help="the scene to add the room to (default: " + ("the open file" if inside_blender
                                                                        else "an empty scene") + ")")
    room.add_argument("--clicks", required=True, metavar="CLICKS.json", help="the click file")
    room.add_argument("--save", required=True, metavar="OUT.blend", help="where to save the scene with the room")
    room.add_argument("--out", required=True, metavar="DIR", help="output folder (created if needed)")
    room.add_argument("--panorama", metavar="FILE", help="make the world show this HDR panorama (EXR, HDR)")
    room.add_argument("--camera-height", type=float, metavar="M",
                      help="the camera's height above the floor in metres (replaces the click file's)")
    room.add_argument("--ceiling-height", type=float, default=None, metavar="M",
                      help="the ceiling's height where the click file has no ceiling point (default 2.5)")
    room.add_argument("--snap", action="store_true",
                      help="first move the floor corners onto the wall-floor edges the panorama shows near them "
                           "(walls it hides keep their clicks); room.json keeps the clicks as given under snapped")
    room.add_argument("--object-at", nargs=2, type=float, metavar=("X", "Y"),
                      help="Object from Photo: also fit a proxy to the object clicked at pixel (X, Y) of the "
                           "click file's panorama, standing on the floor, and mark it for removal")
    room.add_argument("--object-name", default="Object", metavar="NAME", help="that proxy's name (default: Object)")
    room.set_defaults(run=_room, inside_blender=inside_blender)


def _room(args: argparse.Namespace) -> int:
    import dataclasses

    import bpy

    from ..io import exr, outputs
    from ..roommatch import clicks as click_file
    from ..roommatch.diagnostics import room_picture
    from ..roommatch.fit import DEFAULT_CEILING_HEIGHT, fit_room
    from ..roommatch.object_shapes import object_proxy
    from ..roommatch.photo_edges import edge_offsets
    from ..roommatch.refine import refine_clicks
    from . import reader, room_builder
    from .blend_file import open_blend

    try:
        with open(args.clicks, encoding="utf-8") as handle:
            clicks = click_file.from_json(handle.read())
    except OSError as error:
        raise DimredError(f"cannot read the click file {args.clicks}: {error.strerror}") from None
    if args.camera_height is not None:
        clicks = dataclasses.replace(clicks, camera_height=args.camera_height, known_length=None)
    save = os.path.abspath(args.save)
    if not os.path.isdir(os.path.dirname(save)):
        raise DimredError(f"no folder to save {save} in")
    if args.blend:
        open_blend(args.blend)
    elif not args.inside_blender:
        bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    if args.panorama:
        room_builder.show_panorama(scene, os.path.abspath(args.panorama))
    ceiling = DEFAULT_CEILING_HEIGHT if args.ceiling_height is None else args.ceiling_height
    rotation = room_builder.panorama_rotation(scene)
    try:
        panorama, missing = reader.panorama_pixels(scene), ""
    except DimredError as error:
        if args.snap:
            raise
        panorama, missing = None, str(error)
    report = {}
    if args.snap:
        clicked = clicks
        clicks, shown = refine_clicks(panorama, clicks, fit_room(clicks, rotation=rotation, ceiling_height=ceiling),
                                      rotation=rotation)
        report["snapped"] = {"clicked": clicked.to_dict()["floor"], "walls_snapped": shown.tolist()}
    room = room_builder.match_room(scene, clicks, ceiling_height=ceiling)
    if hasattr(scene, "dimred_room"):  # the add-on is registered: its panel shows the clicks
        scene.dimred_room.load(clicks)
        scene.dimred_room.matched = True
    report.update(room=room.summary(), clicks=clicks.to_dict())
    objects = clicks.objects
    if args.object_at is not None:
        objects += (click_file.ObjectClicks(args.object_name, click=tuple(args.object_at)),)
    solids = []
    for item in objects:
        if panorama is None:
            raise DimredError(f"the object '{item.name}' needs the panorama: {missing}")
        proxy = object_proxy(panorama, item, click_size=(clicks.width, clicks.height), probe=room.probe,
                             rotation=rotation, inside=room.corners)
        obj = room_builder.proxy_object(scene, proxy.solid.mesh(item.name))
        if hasattr(scene, "dimred"):
            scene.dimred.mark(obj)
        report.setdefault("objects", []).append({"name": obj.name, **proxy.summary()})
        solids.append(proxy.solid)
    writers = {}
    if panorama is None:
        report["diagnostics"] = f"no room_diagnostics.png: {missing}"
    else:
        report["photo_edges"] = edge_offsets(panorama, room, rotation=rotation).summary()
        picture = room_picture(panorama, room, clicks, solids=tuple(solids), rotation=rotation)
        writers["room_diagnostics.png"] = lambda path: exr.write_png(path, picture)
    writers["room.json"] = outputs.json_writer(report)
    outputs.write_files(args.out, writers, stale=("room_diagnostics.png",))
    try:
        bpy.ops.wm.save_as_mainfile(filepath=save, copy=True)
    except RuntimeError as error:
        raise DimredError(f"cannot save {save}: {str(error).strip()}") from None
    worst = float(np.max(room.corner_errors))
    print(f"dimred: matched the room: {len(clicks.floor)} corners, camera {room.camera_height:.3f} m, "
          f"ceiling {room.ceiling_height:.3f} m, corners within {worst:.2f} px; saved {save}, wrote {args.out}",
          flush=True)
    return 0
