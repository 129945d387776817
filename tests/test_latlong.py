"""The lat-long mapping: its algebra, and proof that it is the one Cycles renders (DESIGN 2).

The Cycles tests render a world whose Environment Texture holds random texels (Closest
interpolation) through an equirectangular camera and require every render pixel to equal the
texel `addon.geometry.latlong` picks for that pixel's direction, with and without a Mapping node.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from addon.geometry import latlong

TEXTURE_W, TEXTURE_H = 64, 32
# A render size prime to the texture's: pixel centres fall everywhere inside texels, so a
# mapping off by a hundredth of a texel would pick the neighbour somewhere.
RENDER_W, RENDER_H = 97, 49


def _random_directions(n: int, seed: int = 0) -> np.ndarray:
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def _rotation(seed: int) -> np.ndarray:
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def test_direction_uv_round_trip():
    d = _random_directions(1000)
    for rotation in (None, _rotation(1)):
        u, v = latlong.direction_to_uv(d, rotation)
        assert np.all((u >= 0) & (u <= 1) & (v >= 0) & (v <= 1))
        np.testing.assert_allclose(latlong.uv_to_direction(u, v, rotation), d, atol=1e-12)


def test_uv_direction_round_trip_and_axes():
    rng = np.random.default_rng(2)
    u, v = rng.uniform(0.001, 0.999, 500), rng.uniform(0.001, 0.999, 500)
    u2, v2 = latlong.direction_to_uv(latlong.uv_to_direction(u, v))
    np.testing.assert_allclose(u2, u, atol=1e-12)
    np.testing.assert_allclose(v2, v, atol=1e-12)
    # +X is the image centre, +Y left of it (u = 0.25), up is v = 1, the seam is at -X.
    u, v = latlong.direction_to_uv(np.array([[1.0, 0, 0], [0, 1, 0], [0, 0, 1], [-1, -1e-9, 0]]))
    np.testing.assert_allclose(u[:3], [0.5, 0.25, 0.5], atol=1e-12)
    np.testing.assert_allclose(v, [0.5, 0.5, 1.0, 0.5], atol=1e-12)
    assert u[3] == pytest.approx(1.0, abs=1e-9)


def test_pixel_directions_are_unit_and_top_row_is_up():
    d = latlong.pixel_directions(16, 8)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0, atol=1e-12)
    assert np.all(d[0, :, 2] > 0.9) and np.all(d[-1, :, 2] < -0.9)


@pytest.mark.parametrize("size", [(8, 4), (64, 32), (2048, 1024)])
def test_pixel_solid_angles_sum_to_the_sphere(size):
    width, height = size
    omega = latlong.pixel_solid_angles(width, height)
    assert omega.shape == (height, 1)
    assert omega.sum() * width == pytest.approx(4.0 * math.pi, rel=1e-12)


def test_sample_bilinear_wraps_the_seam_and_clamps_the_poles():
    image = np.zeros((4, 8, 3))
    image[:, 0] = 1.0  # first column
    image[:, -1] = 3.0  # last column
    image[0, 3] = 5.0  # top row, away from the seam
    at_seam = latlong.sample_bilinear(image, np.array([0.0, 1.0]), np.array([0.375, 0.375]))
    np.testing.assert_allclose(at_seam, 2.0)  # halfway between the first and the last column
    pole = latlong.sample_bilinear(image, np.array(3.5 / 8), np.array(1.0))
    np.testing.assert_allclose(pole, 5.0)  # clamped to the top row, not wrapped to the bottom


def test_sample_nearest_wraps_the_seam_and_clamps_the_poles():
    image = np.arange(4 * 8, dtype=float).reshape(4, 8, 1)
    values = latlong.sample_nearest(image, np.array([-0.01, 1.0, 0.5, 0.5]), np.array([0.5, 0.5, 1.0, 0.0]))
    np.testing.assert_array_equal(values[:, 0], [image[2, 7, 0], image[2, 0, 0], image[0, 4, 0], image[3, 4, 0]])


@pytest.fixture
def random_texture(tmp_path):
    """A 64 x 32 EXR of random texel colours and its pixels (top row first)."""
    from addon.io.exr import write_exr

    pixels = np.random.default_rng(7).random((TEXTURE_H, TEXTURE_W, 3)).astype(np.float32)
    path = tmp_path / "texels.exr"
    write_exr(path, pixels)
    return path, pixels


def _boundary_margin(u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Distance, in texels, of (u, v) from the nearest texel edge."""
    x, y = (u * TEXTURE_W) % 1.0, ((1.0 - v) * TEXTURE_H) % 1.0
    return np.minimum(np.minimum(x, 1.0 - x), np.minimum(y, 1.0 - y))


def _assert_render_matches(render: np.ndarray, texels: np.ndarray, rotation: np.ndarray | None) -> None:
    u, v = latlong.direction_to_uv(latlong.pixel_directions(RENDER_W, RENDER_H), rotation)
    expected = latlong.sample_nearest(texels, u, v)
    # On a texel edge float32 (Cycles) and float64 (here) may break the tie differently.
    decided = _boundary_margin(u, v) > 1e-3
    assert decided.mean() > 0.95
    mismatched = decided & np.any(render != expected, axis=-1)
    assert not mismatched.any(), f"{mismatched.sum()} pixels differ, first at {np.argwhere(mismatched)[:5].tolist()}"
    # The proof covers the seam (first and last column) and the rows next to the poles.
    for edge in (decided[:, 0], decided[:, -1], decided[0], decided[-1]):
        assert edge.mean() > 0.9


@pytest.mark.slow
def test_cycles_renders_the_latlong_mapping(random_texture, panorama_world, render_world):
    import bpy

    path, texels = random_texture
    image = bpy.data.images.load(str(path))
    panorama_world(image)
    _assert_render_matches(render_world(RENDER_W, RENDER_H), texels, None)


@pytest.mark.slow
def test_cycles_render_texel_for_texel_at_texture_size(random_texture, panorama_world, render_world):
    import bpy

    path, texels = random_texture
    panorama_world(bpy.data.images.load(str(path)))
    render = render_world(TEXTURE_W, TEXTURE_H)
    # Same size: each render pixel is the texel at the same row and column, exactly.
    np.testing.assert_array_equal(render, texels)


MAPPINGS = [
    ("POINT", (0.0, 0.0, 40.0), (1.0, 1.0, 1.0)),
    ("POINT", (25.0, -60.0, 40.0), (-2.0, 2.0, 2.0)),
    ("VECTOR", (30.0, 15.0, -70.0), (1.0, 1.0, 1.0)),
    ("TEXTURE", (25.0, -60.0, 40.0), (0.5, -0.5, 0.5)),
    ("NORMAL", (-10.0, 35.0, 120.0), (1.0, 1.0, -1.0)),
]


@pytest.mark.slow
@pytest.mark.parametrize("kind, degrees, scale", MAPPINGS)
def test_cycles_renders_the_mapping_rotation_of_the_bridge(random_texture, panorama_world, render_world, kind, degrees, scale):
    import bpy

    from addon.blender import reader as bridge

    path, texels = random_texture
    tree = panorama_world(bpy.data.images.load(str(path)), (kind, tuple(map(math.radians, degrees)), scale))
    rotation = bridge.texture_rotation(tree.nodes["Environment Texture"])
    _assert_render_matches(render_world(RENDER_W, RENDER_H), texels, rotation)


def test_mapping_rotation_sign_convention(panorama_world):
    """Point mapping, +40 degrees about Z: world direction d samples the texture at R d with
    R the right-handed rotation, so world +X shows the texel 40 degrees towards +Y (u = 0.5 - 40/360)."""
    import bpy

    from addon.blender import reader as bridge

    image = bpy.data.images.new("t", 8, 4, float_buffer=True)
    tree = panorama_world(image, ("POINT", (0.0, 0.0, math.radians(40.0)), (1.0, 1.0, 1.0)))
    rotation = bridge.texture_rotation(tree.nodes["Environment Texture"])
    c, s = math.cos(math.radians(40.0)), math.sin(math.radians(40.0))
    np.testing.assert_allclose(rotation, [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-7)
    u, v = latlong.direction_to_uv(np.array([1.0, 0.0, 0.0]), rotation)
    assert (float(u), float(v)) == pytest.approx((0.5 - 40.0 / 360.0, 0.5))
