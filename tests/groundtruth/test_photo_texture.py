"""The floor albedo projected from a photograph (numpy only, no rendering)."""
from __future__ import annotations

import numpy as np
import pytest

from addon.geometry.latlong import pixel_directions
from scenes import photo_texture as P
from scenes.spec import Photo, Room

ROOM = Room(lo=(-2.0, -1.0, 0.0), hi=(2.0, 1.0, 2.5))


def _panorama(width: int = 256) -> np.ndarray:
    """Grey, with one quadrant of azimuths red: directions towards +x, +y (u in [0.25, 0.5))."""
    d = pixel_directions(width, width // 2)
    image = np.full(d.shape, 0.5)
    image[(d[..., 0] > 0) & (d[..., 1] > 0)] = (1.0, 0.1, 0.1)
    return image


def test_texels_cover_the_floor_top_row_at_the_far_y() -> None:
    x, y = P.texel_centres(ROOM, 0.5)
    assert x.shape == (4, 8)
    np.testing.assert_allclose(x[0], np.arange(-1.75, 2.0, 0.5))
    np.testing.assert_allclose(y[:, 0], [0.75, 0.25, -0.25, -0.75])


def test_the_floor_shows_the_photograph_in_the_direction_of_each_point() -> None:
    photo = Photo("any.exr", texel=0.05, median=0.35, ceiling=0.9)
    albedo = P.floor_albedo(_panorama(), ROOM, photo)
    x, y = P.texel_centres(ROOM, photo.texel)
    red = albedo[..., 0] > 2 * albedo[..., 1]
    # The +x, +y quadrant seen from the camera above the origin, away from its edges.
    inside = (x > 0.1) & (y > 0.1)
    outside = (x < -0.1) | (y < -0.1)
    assert red[inside].all() and not red[outside].any()
    # Scaled so that the floor's median luminance is the photo's `median`, clipped at `ceiling`.
    luminance = albedo @ np.array([0.2126, 0.7152, 0.0722])
    assert np.median(luminance) == pytest.approx(0.35, rel=1e-3)
    assert albedo.max() <= 0.9 and albedo.dtype == np.float32


def test_yaw_and_origin_move_what_the_floor_shows() -> None:
    # Turned by 90 degrees, the red quadrant moves from +x +y to -x +y; moved to (1, 0), the
    # camera puts its boundary at x = 1.
    x, y = P.texel_centres(ROOM, 0.05)
    turned = P.floor_albedo(_panorama(), ROOM, Photo("any.exr", texel=0.05, yaw=90.0))
    red = turned[..., 0] > 2 * turned[..., 1]
    assert red[(x < -0.1) & (y > 0.1)].all() and not red[(x > 0.1) | (y < -0.1)].any()
    moved = P.floor_albedo(_panorama(), ROOM, Photo("any.exr", texel=0.05, origin=(1.0, 0.0)))
    red = moved[..., 0] > 2 * moved[..., 1]
    assert red[(x > 1.1) & (y > 0.1)].all() and not red[(x < 0.9) | (y < -0.1)].any()


def test_bilinear_sampling_wraps_at_the_seam() -> None:
    image = np.zeros((2, 4, 3))
    image[:, 0] = 1.0
    # u = 0 lies between the last column and the first: half of each.
    np.testing.assert_allclose(P.sample_bilinear(image, np.array([0.0]), np.array([0.5])), [[0.5, 0.5, 0.5]])


def test_a_missing_photograph_is_named() -> None:
    with pytest.raises(FileNotFoundError, match=r"no_such\.exr"):
        P.photo_path("no_such.exr")
