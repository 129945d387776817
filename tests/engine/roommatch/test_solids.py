"""Extruded proxies: a prism's silhouette traced from the probe, and closed meshes whose normals
point outwards."""
from __future__ import annotations

import numpy as np
import pytest

from addon.geometry.latlong import pixel_directions
from addon.roommatch.object_box import BoxFit, silhouette
from addon.roommatch.solids import Solid, inside_polygon, prism_silhouette

BOX = BoxFit(bottom=np.array([1.8, 0.6, 0.0]), size=np.array([0.8, 0.7, 0.9]), turn=np.radians(20.0),
             agreement=0.0, outline_pixels=0)


@pytest.mark.parametrize("camera", [1.5, 0.5])  # above the box's top, and below it
def test_a_rectangular_prism_shows_the_box_silhouette(camera: float) -> None:
    rays = pixel_directions(512, 256)
    box = silhouette(np.array([1.8, 0.6, np.log(0.8), np.log(0.7), np.log(0.9), np.radians(20.0)]), rays, camera)
    prism = prism_silhouette(BOX.corners()[:4, :2], 0.9, rays, camera)
    assert box.sum() > 500
    assert np.count_nonzero(box != prism) <= 0.01 * box.sum()  # rays grazing an edge may go either way


def test_a_notched_footprint_shows_its_notch() -> None:
    # An L seen from above: the notch's floor is seen, the arms are not.
    ell = np.array([(1.0, -1.0), (3.0, -1.0), (3.0, 1.0), (2.0, 1.0), (2.0, 0.0), (1.0, 0.0)])
    rays = pixel_directions(512, 256)
    shown = prism_silhouette(ell, 0.5, rays, 1.5)
    down = rays[..., 2] < 0
    foot = rays[..., :2] * (1.5 / -np.where(down, rays[..., 2], -1.0))[..., None]
    assert not shown[down & inside_polygon(foot, np.array([(1.1, 0.1), (1.9, 0.1), (1.9, 0.9), (1.1, 0.9)]))
                     ].any()
    assert shown[down & inside_polygon(foot, np.array([(1.1, -0.9), (2.9, -0.9), (2.9, -0.1), (1.1, -0.1)]))].all()


def _volume(solid: Solid) -> float:
    """The mesh's signed volume (positive when every face's normal points outwards)."""
    v = solid.vertices()
    total = 0.0
    for face in solid.faces():
        for i in range(1, len(face) - 1):
            total += float(np.dot(v[face[0]], np.cross(v[face[i]], v[face[i + 1]])))
    return total / 6.0


def test_meshes_are_closed_with_outward_normals() -> None:
    prism = Solid.prism(BOX.corners()[:4, :2], 0.0, 0.9)
    assert _volume(prism) == pytest.approx(0.8 * 0.7 * 0.9)
    clockwise = Solid.prism(BOX.corners()[:4, :2][::-1], 0.0, 0.9)
    assert _volume(clockwise) == pytest.approx(0.8 * 0.7 * 0.9)
    # A profile standing upright, swept across: a seat 0.45 m high before a back 0.9 m high.
    u, z = np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])
    step = Solid(np.array([(0, 0), (0.7, 0), (0.7, 0.9), (0.5, 0.9), (0.5, 0.45), (0, 0.45)]),
                 np.array([1.0, 0.0, 0.0]), np.stack([u, z, np.cross(u, z)]), 0.8)
    assert _volume(step) == pytest.approx(0.8 * (0.5 * 0.45 + 0.2 * 0.9))
    edges = step.edges()
    assert edges.shape == (18, 2, 3)
    assert np.all(np.linalg.norm(edges[:, 1] - edges[:, 0], axis=1) > 0.1)
