"""`python -m scenes.room_job DIR`: render the `RoomScene` in DIR/room.json to DIR/panorama.exr.

Diffuse walls, a darker floor, a lighter ceiling, a dark door quad 5 mm in front of its wall and
yellow boxes on the floor, lit by one area lamp under the ceiling; few samples and bounces: the render is looked at for
its edges, not its light. The camera is the ground-truth renders' panoramic camera
(`scenes.build`), so the render is the panorama the world shows through its Mapping rotation.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import bpy
import numpy as np

from .build import _camera, _diffuse, _mesh_object, configure_cycles, set_black_world
from .images import read_exr, write_exr
from .rooms import RoomScene
from .spec import Render


def build_room(room: RoomScene) -> None:
    scene = bpy.context.scene
    configure_cycles(scene, Render(room.width, room.height, room.samples, max_bounces=3))
    c = [tuple(p) for p in room.corners]
    n = len(c)
    floor = [(x, y, 0.0) for x, y in c]
    top = [(x, y, room.ceiling) for x, y in c]
    _mesh_object(scene, "Floor", floor, [tuple(range(n))], _diffuse("Floor", (0.35, 0.3, 0.25)))
    _mesh_object(scene, "Ceiling", top, [tuple(reversed(range(n)))], _diffuse("Ceiling", (0.85, 0.85, 0.85)))
    _mesh_object(scene, "Walls", floor + top, [(i, n + i, n + (i + 1) % n, (i + 1) % n) for i in range(n)],
                 _diffuse("Walls", (0.7, 0.68, 0.64)))
    door = room.door()
    a, b = np.asarray(c[room.door_wall]), np.asarray(c[(room.door_wall + 1) % n])
    inwards = np.array([-(b - a)[1], (b - a)[0]]) / np.linalg.norm(b - a)  # left of a counter-clockwise wall
    door[:, :2] += 0.005 * inwards
    _mesh_object(scene, "Door", [tuple(p) for p in door], [(0, 3, 2, 1)], _diffuse("Door", (0.12, 0.07, 0.04)))
    chair = _diffuse("Box", (0.55, 0.45, 0.08))
    for i, (x, y, w, d, h, turn) in enumerate(room.boxes):
        a = np.radians(turn)
        axes = np.array([[np.cos(a), np.sin(a)], [-np.sin(a), np.cos(a)]])
        foot = np.array([[-w, -d], [w, -d], [w, d], [-w, d]]) / 2 @ axes + (x, y)
        corners = [(px, py, z) for z in (0.0, h) for px, py in foot]
        _mesh_object(scene, f"Box.{i:03d}", corners,
                     [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)], chair)
    light = bpy.data.lights.new("Lamp", "AREA")
    light.size = 0.6
    light.energy = 250.0
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = room.lamp
    scene.collection.objects.link(lamp)
    _camera(scene, room)
    set_black_world(scene)


def main(folder: Path) -> None:
    data = json.loads((folder / "room.json").read_text())
    room = RoomScene(**{k: tuple(map(tuple, v)) if k in ("corners", "boxes") else tuple(v) if isinstance(v, list)
                        else v for k, v in data.items()})
    bpy.ops.wm.read_factory_settings(use_empty=True)
    build_room(room)
    scene = bpy.context.scene
    scene.render.filepath = str(folder / "raw.exr")
    bpy.ops.render.render(write_still=True)
    write_exr(folder / "panorama.exr", read_exr(folder / "raw.exr"))
    (folder / "raw.exr").unlink()


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python -m scenes.room_job DIR")
    main(Path(sys.argv[1]))
