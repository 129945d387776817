"""The paint under a removed object against the paint around it (numpy only, no rendering)."""
from __future__ import annotations

import math

import numpy as np

from addon.geometry.latlong import pixel_directions
from addon.geometry.raycast import first_hits
from addon.removal.target import scene_geometry
from scenes.printed import albedo_level, printed_level
from scenes.spec import get
from tests.engine import tiny_room

WIDTH = 256


def _box_pixels(scene) -> np.ndarray:
    """(h, w) the pixels whose first hit is the tiny room's box."""
    geo = scene_geometry(scene)
    d = pixel_directions(WIDTH, WIDTH // 2).reshape(-1, 3)
    hit, _ = first_hits(np.zeros_like(d), d, geo.triangles)
    box = scene.object_names.index("Box")
    return ((hit >= 0) & (geo.tri_object[np.maximum(hit, 0)] == box)).reshape(WIDTH // 2, WIDTH)


def _behind_box(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Where the floor point (x, y) lies behind the box seen from the probe."""
    points = np.stack([x, y, np.zeros_like(x)], axis=-1)
    origin = np.asarray(tiny_room.CENTER)
    d = points - origin
    t = tiny_room._ray_box(origin, d / np.linalg.norm(d, axis=-1, keepdims=True), *tiny_room.BOX)
    return t < np.linalg.norm(d, axis=-1) - 1e-6


def test_a_floor_painted_alike_everywhere_reads_one() -> None:
    scene = tiny_room.scene_data(WIDTH, WIDTH // 2)
    level = albedo_level(scene, _box_pixels(scene), "Box", lambda x, y: np.full_like(x, 0.4))
    assert abs(level - 1.0) < 1e-12


def test_paint_only_the_object_hides_reads_its_share_of_the_paint_around() -> None:
    # Painted at 0.2 exactly where the box hides the floor from the probe, 0.4 everywhere the
    # probe sees: the floor under the object at half the level around it.
    scene = tiny_room.scene_data(WIDTH, WIDTH // 2)
    level = albedo_level(scene, _box_pixels(scene), "Box", lambda x, y: np.where(_behind_box(x, y), 0.2, 0.4))
    assert abs(level - 0.5) < 0.02


def test_a_floor_not_textured_from_a_photograph_has_no_level() -> None:
    assert math.isnan(printed_level(get("basic_box"), None, np.zeros((4, 8), bool)))
