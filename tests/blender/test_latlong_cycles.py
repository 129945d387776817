"""The lat-long mapping of `addon.geometry.latlong` is the one Cycles renders.

The Cycles tests render a world whose Environment Texture holds random texels (Closest
interpolation) through an equirectangular camera and require every render pixel to equal the
texel `addon.geometry.latlong` picks for that pixel's direction, with and without a Mapping node.
A render with Closest interpolation shows, at each pixel, the texel `latlong.uv_to_pixel` names
for the pixel's (u, v): the engine's own texel lookup is the oracle.
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
    expected = texels[latlong.uv_to_pixel(u, v, TEXTURE_W, TEXTURE_H)]
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
def test_cycles_renders_the_mapping_rotation_of_the_bridge(random_texture, panorama_world, render_world,
                                                            kind, degrees, scale):
    import bpy

    from addon.blender import reader

    path, texels = random_texture
    tree = panorama_world(bpy.data.images.load(str(path)), (kind, tuple(map(math.radians, degrees)), scale))
    rotation = reader.texture_rotation(tree.nodes["Environment Texture"])
    _assert_render_matches(render_world(RENDER_W, RENDER_H), texels, rotation)


def test_mapping_rotation_sign_convention(panorama_world):
    """Point mapping, +40 degrees about Z: world direction d samples the texture at R d with
    R the right-handed rotation, so world +X shows the texel 40 degrees towards +Y (u = 0.5 - 40/360)."""
    import bpy

    from addon.blender import reader

    image = bpy.data.images.new("t", 8, 4, float_buffer=True)
    tree = panorama_world(image, ("POINT", (0.0, 0.0, math.radians(40.0)), (1.0, 1.0, 1.0)))
    rotation = reader.texture_rotation(tree.nodes["Environment Texture"])
    c, s = math.cos(math.radians(40.0)), math.sin(math.radians(40.0))
    np.testing.assert_allclose(rotation, [[c, -s, 0], [s, c, 0], [0, 0, 1]], atol=1e-7)
    u, v = latlong.direction_to_uv(np.array([1.0, 0.0, 0.0]), rotation)
    assert (float(u), float(v)) == pytest.approx((0.5 - 40.0 / 360.0, 0.5))
