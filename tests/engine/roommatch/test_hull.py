"""The one-view hull: carved from a box by the outline's cone from the probe, its mesh is closed
with outward normals and its traced silhouette is the outline wherever the box covers it; an
armchair with arms, which no box nor stepped box fits, gets a carved proxy from one click."""
from __future__ import annotations

import numpy as np
import pytest

from addon.geometry import solid
from addon.roommatch.hull import Wedges, carve, traced, vertical_columns
from addon.roommatch.object_box import Outline, agreement, silhouette
from addon.roommatch.object_shapes import object_from_click
from addon.roommatch.projection import click_directions, project
from tests.engine.roommatch.room_truth import flat_panorama, rotation_z, with_box

PROBE = np.array([0.0, 0.0, 1.5])
W, H = 1024, 512
TURN = np.radians(20.0)
BOX = np.array([1.8, 0.6, np.log(0.8), np.log(0.7), np.log(0.9), TURN])


def _volume(corners: np.ndarray) -> float:
    return float(np.einsum("ij,ij->i", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])).sum() / 6.0)


def _outline(params: np.ndarray, rotation: np.ndarray) -> Outline:
    """The outline a box shows over a window round it, the world turned by `rotation`."""
    x, y = project(np.array([params[0], params[1], -1.0]), W, H, rotation)
    grid = np.stack(np.meshgrid(np.arange(x - 80, x + 80), np.arange(y - 100, y + 60)), axis=-1)
    directions = click_directions(np.round(grid), W, H, rotation)
    shown = silhouette(params, directions, PROBE[2])
    return Outline(shown, directions, PROBE[2], PROBE, 0.0, None, rotation)


@pytest.mark.parametrize("turned", [0.0, 40.0])
def test_the_hull_of_a_box_in_that_box_is_the_box(turned: float) -> None:
    outline = _outline(BOX, rotation_z(turned))
    hull = carve(outline, Wedges.of(outline), BOX[None])
    corners = hull.triangle_corners()
    assert solid.closed(corners, 1e-5)
    # Its pixels' edges are half a pixel outside their centres: the hull is the box, to a few per cent.
    assert _volume(corners) == pytest.approx(0.8 * 0.7 * 0.9, rel=0.03)
    assert agreement(traced(hull, outline), outline.shown) == 1.0
    assert len(hull.triangles) < 3000


def test_a_world_tilted_off_the_vertical_is_not_carved() -> None:
    # Its pixel columns are no vertical half-planes: the hull's sections would not be its pixels'.
    a = np.radians(10.0)
    tilted = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(a), -np.sin(a)], [0.0, np.sin(a), np.cos(a)]])
    assert vertical_columns(_outline(BOX, rotation_z(40.0)))
    assert not vertical_columns(_outline(BOX, tilted))


def test_the_hull_in_a_bigger_box_shows_the_outline_and_is_smaller_than_the_box() -> None:
    outline = _outline(BOX, rotation_z(0.0))
    bigger = BOX + np.array([0.0, 0.0, np.log(1.3), np.log(1.3), np.log(1.2), 0.0])
    hull = carve(outline, Wedges.of(outline), bigger[None])
    corners = hull.triangle_corners()
    assert solid.closed(corners, 1e-5)
    assert 0.8 * 0.7 * 0.9 < _volume(corners) < 0.8 * 0.7 * 0.9 * 1.3**2 * 1.2
    assert agreement(traced(hull, outline), outline.shown) == 1.0


def test_an_armchair_with_arms_gets_a_carved_proxy() -> None:
    # A seat 0.45 m high between two arms 0.7 m high, before a narrower back 1.1 m high.
    across = np.array([np.cos(TURN), np.sin(TURN)])
    along = np.array([-np.sin(TURN), np.cos(TURN)])
    centre = np.array([1.8, 0.6])
    if np.dot(centre + along, centre) < np.dot(centre, centre):
        along = -along  # the back behind the seat, seen from the probe
    parts = [(centre - 0.1 * along, 0.56, 0.5, 0.45), (centre + 0.25 * along, 0.4, 0.2, 1.1),
             (centre - 0.34 * across - 0.1 * along, 0.12, 0.5, 0.7),
             (centre + 0.34 * across - 0.1 * along, 0.12, 0.5, 0.7)]
    panorama = flat_panorama(np.array([(-2.0, -1.5), (3.0, -1.5), (3.0, 2.5), (-2.0, 2.5)]), 2.6, PROBE, W, H)
    for (x, y), width, depth, tall in parts:
        panorama = with_box(panorama, np.array([x, y, np.log(width), np.log(depth), np.log(tall), TURN]), 1.5,
                            (0.7, 0.6, 0.1))
    click = tuple(np.round(project(np.append(centre - 0.1 * along, 0.3 - 1.5), W, H)))
    proxy = object_from_click(panorama, click, click_size=(W, H), probe=PROBE)
    assert proxy.kind.startswith("carved") and proxy.agreement >= 0.95, (proxy.kind, proxy.agreement)
    assert proxy.details["base"]["agreement"] < 0.95
    corners = proxy.solid.triangle_corners()
    assert solid.closed(corners, 1e-5) and len(corners) < 4000
    assert _volume(corners) > 0.0
    assert proxy.size[2] == pytest.approx(1.1, rel=0.1)  # the cone reaches above the back in front of it
