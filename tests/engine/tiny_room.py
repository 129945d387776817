"""The tiny procedural room as plain arrays, for engine tests that must run without Blender.

A 4 x 4 x 3 m room (floor, walls and ceiling), a square lamp in the ceiling, a red 0.6 m box on
the floor, and a lat-long HDRI seen from the probe centre that matches it roughly (the lamp, the
box, and the box's shadow on a tiled floor). Meant to be fast, not exact.

`tests.blender.tiny_scene` builds the same room in Blender from the same constants and faces;
`scene_data` here returns what `addon.blender.reader.read_scene` reads from that scene, and
`tests/blender/test_tiny_room_contract.py` holds the two to each other. This module imports
only numpy and OpenEXR at the top: the smoke test of the installed extension imports it in an
interpreter whose engine must come from the installed extension, not from this checkout.
"""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from addon.scene import SceneData

CENTER = (0.0, 0.0, 1.2)
ROOM = ((-2.0, -2.0, 0.0), (2.0, 2.0, 3.0))
BOX = ((0.7, -0.3, 0.0), (1.3, 0.3, 0.6))
# A second, smaller box some tests add to the room; the panorama shows it only when asked to.
CRATE = ((-0.9, -0.8, 0.0), (-0.6, -0.5, 0.3))
LAMP_HALF = 0.3
LAMP_Z = ROOM[1][2] - 0.01


def write_exr(path: str | Path, rgb: np.ndarray) -> None:
    """RGB float32 EXR, row 0 at the top (written with OpenEXR, independent of the engine)."""
    import OpenEXR

    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {"RGB": np.ascontiguousarray(rgb, dtype=np.float32)}) as exr:
        exr.write(str(path))


def read_exr(path: str | Path) -> np.ndarray:
    """(H, W, 3) float32 pixels of an RGB EXR, row 0 at the top."""
    import OpenEXR

    with OpenEXR.File(str(path)) as exr:
        channels = exr.channels()
        if "RGB" in channels:
            return np.asarray(channels["RGB"].pixels, dtype=np.float32)
        return np.stack([np.asarray(channels[c].pixels, dtype=np.float32) for c in "RGB"], axis=-1)


def _ray_box(origin: np.ndarray, d: np.ndarray, lo: tuple, hi: tuple) -> np.ndarray:
    """Entry distance of rays into an axis-aligned box, inf where they miss (slab test)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (np.asarray(lo) - origin) / d
        t2 = (np.asarray(hi) - origin) / d
    near = np.nanmax(np.minimum(t1, t2), axis=-1)
    far = np.nanmin(np.maximum(t1, t2), axis=-1)
    return np.where((far >= np.maximum(near, 0.0)) & (near > 0.0), near, np.inf)


def synthetic_hdri(width: int = 64, height: int = 32, *, crate: bool = False) -> np.ndarray:
    """(H, W, 3) float32 radiance of the room seen from CENTER (Blender's equirectangular map),
    with the CRATE standing in it too when `crate` (its shadow left out)."""
    u = (np.arange(width) + 0.5) / width
    v = 1.0 - (np.arange(height) + 0.5) / height
    phi = (0.5 - u[None, :]) * 2.0 * np.pi
    theta = (1.0 - v[:, None]) * np.pi
    d = np.stack(np.broadcast_arrays(np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)), -1)
    c = np.asarray(CENTER)

    # Leaving a convex room from inside: the nearest positive wall distance per axis.
    with np.errstate(divide="ignore"):
        t_wall = np.where(d > 0, (np.asarray(ROOM[1]) - c) / d, (np.asarray(ROOM[0]) - c) / d)
    t_wall = np.where(np.isfinite(t_wall) & (t_wall > 0), t_wall, np.inf)
    axis = np.argmin(t_wall, axis=-1)
    t = np.min(t_wall, axis=-1)
    p = c + d * t[..., None]

    rgb = np.full(d.shape, 0.6, dtype=np.float32)  # walls
    floor = (axis == 2) & (d[..., 2] < 0)
    ceiling = (axis == 2) & (d[..., 2] > 0)
    tiles = (np.floor(p[..., 0] / 0.25) + np.floor(p[..., 1] / 0.25)) % 2
    rgb[floor] = (0.35 + 0.2 * tiles[floor])[:, None]
    rgb[ceiling] = 0.5
    lamp = ceiling & (np.abs(p[..., 0]) <= LAMP_HALF) & (np.abs(p[..., 1]) <= LAMP_HALF)
    rgb[lamp] = 25.0

    # The box's shadow from the lamp's centre on the floor.
    to_lamp = np.asarray((0.0, 0.0, LAMP_Z)) - p
    dist = np.linalg.norm(to_lamp, axis=-1)
    shadowed = floor & (_ray_box(p, to_lamp / dist[..., None], *BOX) < dist)
    rgb[shadowed] *= 0.3

    box = _ray_box(c, d, *BOX) < t
    rgb[box] = (0.5, 0.06, 0.05)
    if crate:
        rgb[_ray_box(c, d, *CRATE) < t] = (0.12, 0.3, 0.5)
    return rgb


def box_triangles(lo, hi) -> np.ndarray:
    """(12, 3, 3) triangles of the axis-aligned box from corner `lo` to corner `hi`."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    c = np.array([[x, y, z] for z in (lo[2], hi[2]) for y in (lo[1], hi[1]) for x in (lo[0], hi[0])])
    faces = [(0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5), (0, 4, 5), (0, 5, 1),
             (2, 3, 7), (2, 7, 6), (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3)]
    return c[np.array(faces)]


def box_faces(lo: tuple, hi: tuple) -> tuple[list, list]:
    """Vertices and outward-facing quads of the axis-aligned box from `lo` to `hi`."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    vertices = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
                (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    return vertices, faces


def meshes() -> dict[str, tuple[list, list]]:
    """The room's mesh objects by name: (vertices, polygons) as `tiny_scene.build_scene` hands
    them to Blender, every object at the origin with an identity transform."""
    (x0, y0, _), (x1, y1, _) = ROOM
    room_vertices, room_faces = box_faces(*ROOM)
    h = LAMP_HALF
    return {
        "Floor": ([(x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0)], [(0, 1, 2, 3)]),
        # The room without its floor, faces turned inwards.
        "Room": (room_vertices, [tuple(reversed(f)) for f in room_faces[1:]]),
        "Lamp": ([(-h, -h, LAMP_Z), (-h, h, LAMP_Z), (h, h, LAMP_Z), (h, -h, LAMP_Z)], [(0, 1, 2, 3)]),
        "Box": box_faces(*BOX),
    }


def _triangulate(vertices: list, polygons: list) -> np.ndarray:
    """(T, 3, 3) float64 triangles of convex polygons, as Blender's loop triangles give them:
    polygons in order, each quad (a, b, c, d) split into (a, b, c) and (a, c, d), and vertex
    positions rounded to float32 (Blender stores them so) before widening to float64."""
    positions = np.asarray(vertices, dtype=np.float32).astype(np.float64)
    corners = [(p[0], p[i], p[i + 1]) for p in polygons for i in range(1, len(p) - 1)]
    return positions[np.array(corners)]


def turned(scene: SceneData, columns: int) -> SceneData:
    """`scene` photographed turned by `columns` pixels about the vertical: its panorama rolled
    by as many columns and the world's texture rotation turned back by as much, so the same room
    and the same photograph of it, the seam elsewhere."""
    a = -2.0 * np.pi * columns / scene.hdri.shape[1]
    turn = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    return replace(scene, rotation=turn @ scene.rotation, hdri=np.roll(scene.hdri, columns, axis=1))


def scene_data(width: int, height: int) -> SceneData:
    """The room as `addon.blender.reader.read_scene` reads it from `tiny_scene.build_scene`'s
    scene with a `width` x `height` synthetic HDRI: objects sorted by name (the reader's order),
    identity texture rotation (no Mapping node), the probe centre of the ProbeCenter Empty."""
    from addon.scene import SceneData

    names = sorted(meshes())
    chunks = [_triangulate(*meshes()[name]) for name in names]
    return SceneData(
        hdri=synthetic_hdri(width, height),
        rotation=np.eye(3),
        center=np.asarray(CENTER, dtype=np.float32).astype(np.float64),
        triangles=np.concatenate(chunks),
        tri_object=np.concatenate([np.full(len(c), i, dtype=np.int32) for i, c in enumerate(chunks)]),
        object_names=names,
    )
