"""Surfaces where the photograph shows them: a proxy room whose wall stands 0.2 m behind the
photographed one puts its wall/floor line 3-4 pixels above the photograph's (at 512x256); the
fill follows the photograph's line, not the proxy's."""
from __future__ import annotations

import numpy as np
import pytest

from addon.geometry import latlong
from addon.scene import SceneData
from addon.synthesis.surface_edges import SurfacePlane, find_surface_edges
from tests.engine.tiny_room import _triangulate, box_faces

WIDTH, HEIGHT = 512, 256
CENTER = np.array([0.0, 0.0, 1.2])
ROOM = ((-2.0, -2.0, 0.0), (2.0, 2.0, 3.0))  # the proxy's room
PHOTO_WALL = 1.8  # where the photograph's +X wall stands (the proxy's: 2.0)
BOX = ((1.2, -0.35, 0.0), (1.55, 0.35, 0.75))
WALL, FLOOR = np.array([0.75, 0.72, 0.66]), np.array([0.30, 0.19, 0.11])


def _first_hit(d: np.ndarray, wall_x: float) -> tuple[np.ndarray, np.ndarray]:
    """The distance along unit rays `d` (..., 3) from CENTER to the room with its +X wall at
    `wall_x`, and which face (0-2: the walls along x, y, and the floor or ceiling)."""
    hi = np.array([wall_x, ROOM[1][1], ROOM[1][2]])
    with np.errstate(divide="ignore"):
        t = np.where(d > 0, (hi - CENTER) / d, (np.asarray(ROOM[0]) - CENTER) / d)
    t = np.where(np.isfinite(t) & (t > 0), t, np.inf)
    return t.min(axis=-1), t.argmin(axis=-1)


def _photograph(wall_x: float) -> tuple[np.ndarray, np.ndarray]:
    """(H, W, 3) the room photographed with its +X wall at `wall_x` (pale walls, a planked brown
    floor with grain), the box in it; and (H, W) where it shows the floor."""
    d = latlong.pixel_directions(WIDTH, HEIGHT)
    t, face = _first_hit(d, wall_x)
    p = CENTER + d * t[..., None]
    floor = (face == 2) & (d[..., 2] < 0)
    grain = np.random.default_rng(1).normal(0.0, 0.03, (HEIGHT, WIDTH))[..., None]
    planks = 0.06 * np.sin(p[..., 1] * 2 * np.pi / 0.2)[..., None]
    rgb = np.where(floor[..., None], FLOOR * (1 + planks + grain), WALL * (1 + 0.3 * grain))
    with np.errstate(divide="ignore", invalid="ignore"):
        t1, t2 = (np.asarray(BOX[0]) - CENTER) / d, (np.asarray(BOX[1]) - CENTER) / d
    near, far = np.nanmax(np.minimum(t1, t2), axis=-1), np.nanmin(np.maximum(t1, t2), axis=-1)
    box = (far >= near) & (near > 0) & (near < t)
    rgb[box] = (0.5, 0.45, 0.1)
    return rgb.astype(np.float32), floor & ~box


def _scene(photo: np.ndarray) -> SceneData:
    room_vertices, room_faces = box_faces(*ROOM)
    (x0, y0, _), (x1, y1, _) = ROOM
    meshes = {"Box": box_faces(*BOX),
              "Floor": ([(x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0)], [(0, 1, 2, 3)]),
              "Room": (room_vertices, [tuple(reversed(f)) for f in room_faces[1:]])}
    names = sorted(meshes)
    chunks = [_triangulate(*meshes[n]) for n in names]
    return SceneData(hdri=photo, rotation=np.eye(3), center=CENTER, triangles=np.concatenate(chunks),
                     tri_object=np.concatenate([np.full(len(c), i, dtype=np.int32) for i, c in enumerate(chunks)]),
                     object_names=names)


def _labels(wall_x: float) -> np.ndarray:
    """(H, W) 0 where the room with its +X wall at `wall_x` shows the floor, 1 the +X wall, -1 else."""
    d = latlong.pixel_directions(WIDTH, HEIGHT)
    _, face = _first_hit(d, wall_x)
    return np.where((face == 2) & (d[..., 2] < 0), 0, np.where((face == 0) & (d[..., 0] > 0), 1, -1))


def _object_pixels() -> np.ndarray:
    photo, _ = _photograph(PHOTO_WALL)
    return np.all(np.isclose(photo, (0.5, 0.45, 0.1)), axis=-1)


PLANES = {0: SurfacePlane(np.array([0.0, 0.0, 1.0]), -CENTER[2]),
          1: SurfacePlane(np.array([-1.0, 0.0, 0.0]), -(ROOM[1][0] - CENTER[0]))}


@pytest.mark.parametrize(("wall_x", "shift"), [(PHOTO_WALL, 3.9), (ROOM[1][0], 0.0)])
def test_the_photographs_wall_floor_line_is_found_beside_the_hole(wall_x: float, shift: float) -> None:
    photo, _ = _photograph(wall_x)
    hidden = _object_pixels()
    proxy = _labels(ROOM[1][0])
    edges = find_surface_edges(photo, np.where(hidden, -1, proxy), proxy, hidden, PLANES)
    (edge,) = edges.edges
    assert edge.found and abs(edge.shift - shift) <= 1.0, edge.describe({})
    # every pixel of the hole on the side of the photograph's line: the truth's surfaces
    rows, cols = np.nonzero(hidden & (proxy >= 0))
    d = latlong.pixel_directions_at(rows, cols, WIDTH, HEIGHT)
    assigned = edges.assign(d, proxy[rows, cols])
    truth = _labels(wall_x)[rows, cols]
    assert np.mean(assigned != truth) <= 0.01


def test_a_photograph_without_an_edge_keeps_the_proxys() -> None:
    """A photograph of one colour all over (and its noise) shows no edge: the proxy's is kept."""
    hidden = _object_pixels()
    proxy = _labels(ROOM[1][0])
    photo = np.full((HEIGHT, WIDTH, 3), 0.5, np.float32) * (
        1 + np.random.default_rng(2).normal(0, 0.05, (HEIGHT, WIDTH, 1))).astype(np.float32)
    (edge,) = find_surface_edges(photo, np.where(hidden, -1, proxy), proxy, hidden, PLANES).edges
    assert not edge.found and edge.describe({0: "Floor", 1: "Wall"}) == {"surfaces": ["Floor", "Wall"],
                                                                         "kept": "no edge found"}


@pytest.mark.parametrize("working_width", [WIDTH, WIDTH // 2], ids=["working", "full resolution"])
def test_the_fill_follows_the_photographs_wall_floor_line(working_width: int) -> None:
    """Removed with the proxy's wall 0.2 m behind the photographed one, the hole's pixels between
    the two lines show the wall as the truth does, not the floor's brown: filled on the working
    panorama, and at the panorama's own size above the working width."""
    from addon.pipeline import remove_object

    photo, _ = _photograph(PHOTO_WALL)
    result = remove_object(_scene(photo), "Box", quality="draft", segmentation_band=0, working_width=working_width)
    edited = photo + result.difference
    band = result.hidden_mask & (_labels(ROOM[1][0]) == 0) & (_labels(PHOTO_WALL) == 1)
    assert band.sum() >= 50
    luma = edited[band] @ np.array([0.2126, 0.7152, 0.0722])
    wall, floor = WALL @ np.array([0.2126, 0.7152, 0.0722]), FLOOR @ np.array([0.2126, 0.7152, 0.0722])
    # nearer the wall's luminance than the floor's, pixel by pixel
    assert np.mean(np.abs(luma - wall) < np.abs(luma - floor)) >= 0.9, np.mean(luma)
    assert {"surfaces", "shift_px"} <= set(result.report["surface_edges"][0])
