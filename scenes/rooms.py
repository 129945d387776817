"""Synthetic rooms of known geometry for Match Room, rendered once with Cycles and cached (no bpy).

A `RoomScene` is a floor polygon (any shape, corners counter-clockwise from above), a ceiling
height, a door on one wall, a lamp and the probe centre; `render_room` renders the panorama a
camera at the probe sees (`scenes.room_job`, in a subprocess) into
`.cache/rooms/<key>/panorama.exr` and returns its path. The truth the tests compare with is the
scene itself: its corners, the door's edges, the camera height.
"""
from __future__ import annotations

import dataclasses
import fcntl
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .render import REPO

CACHE_ROOT = REPO / ".cache" / "rooms"
_SOURCES = ("rooms.py", "room_job.py")


@dataclass(frozen=True)
class RoomScene:
    """`corners` (n, 2) of the floor at z = 0, counter-clockwise; a door `door_width` x
    `door_height` centred on wall `door_wall` (corner i to i + 1); `world_rotation_z` the
    world's Mapping rotation in degrees (the render is the panorama such a world shows)."""

    name: str
    corners: tuple[tuple[float, float], ...]
    ceiling: float
    probe: tuple[float, float, float]
    lamp: tuple[float, float, float]
    door_wall: int = 0
    door_width: float = 0.9
    door_height: float = 2.0
    world_rotation_z: float = 0.0
    # Boxes standing on the floor: (x, y, width, depth, height, turn in degrees) each.
    boxes: tuple[tuple[float, float, float, float, float, float], ...] = ()
    width: int = 1024
    height: int = 512
    samples: int = 8

    def key(self) -> str:
        code = "".join((Path(__file__).parent / name).read_text() for name in _SOURCES)
        text = json.dumps(dataclasses.asdict(self), sort_keys=True) + code
        return hashlib.sha1(text.encode()).hexdigest()[:20]

    def door(self) -> np.ndarray:
        """(4, 3) the door's corners: bottom left, bottom right, top right, top left."""
        c = np.asarray(self.corners, dtype=np.float64)
        a, b = c[self.door_wall], c[(self.door_wall + 1) % len(c)]
        along = (b - a) / np.linalg.norm(b - a)
        mid = (a + b) / 2
        left, right = mid - along * self.door_width / 2, mid + along * self.door_width / 2
        return np.array([[*left, 0.0], [*right, 0.0], [*right, self.door_height], [*left, self.door_height]])


ROOMS: dict[str, RoomScene] = {r.name: r for r in (
    # An L-shaped room: the probe in its long arm, the short arm's far corners seen past the
    # inner corner.
    RoomScene("l_room", ((-2.0, -1.6), (3.4, -1.6), (3.4, 0.9), (1.2, 0.9), (1.2, 2.8), (-2.0, 2.8)),
              ceiling=2.6, probe=(0.3, -0.2, 1.55), lamp=(0.5, 0.3, 2.3), door_wall=5),
    # A rectangle turned 25 degrees, seen from 1.2 m through a world rotated by 40 degrees.
    RoomScene("turned_room", ((-1.55, -2.67), (2.98, -0.56), (1.46, 2.7), (-3.07, 0.58)),
              ceiling=2.4, probe=(-0.2, 0.1, 1.2), lamp=(0.3, -0.4, 2.1), door_wall=1,
              world_rotation_z=40.0),
    # A yellow armchair-sized box on a darker floor, 2 m from the probe, for Object from Photo.
    RoomScene("chair_room", ((-2.5, -2.0), (3.0, -2.0), (3.0, 2.2), (-2.5, 2.2)),
              ceiling=2.6, probe=(0.0, 0.0, 1.5), lamp=(0.8, 0.5, 2.3), door_wall=2,
              boxes=((1.8, 0.6, 0.8, 0.7, 0.9, 20.0),)),
)}


def render_room(room: RoomScene, cache_root: Path = CACHE_ROOT) -> Path:
    """The cached panorama (EXR, top row first) of `room`, rendered first if needed."""
    folder = cache_root / room.key()
    path = folder / "panorama.exr"
    if path.exists():
        return path
    cache_root.mkdir(parents=True, exist_ok=True)
    with open(cache_root / ".render.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if path.exists():
            return path
        work = Path(tempfile.mkdtemp(prefix=f"{room.key()}.", suffix=".tmp", dir=cache_root))
        try:
            (work / "room.json").write_text(json.dumps(dataclasses.asdict(room)))
            _render_job(work)
            work.rename(folder)
        finally:
            if work.exists():
                shutil.rmtree(work)
    return path


def _render_job(folder: Path) -> None:
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-m", "scenes.room_job", str(folder)], cwd=REPO, env=env,
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"room render failed (exit {done.returncode}):\n{(done.stdout + done.stderr)[-3000:]}")
