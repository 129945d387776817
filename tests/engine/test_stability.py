"""Stiff and extreme input for the engine, each with a bound: real scenes have lamps far brighter
than anything else, broken pixels and sliver triangles, and the engine must stay finite on them.

The tiny procedural room (`tiny_room`, 64x32 panorama, arrays without Blender) is built once; each
test changes one thing the way an extreme scene would (its size, the HDR range, broken pixels,
broken triangles, a probe at the corner of two surfaces, a black world) and checks that the
output is finite, that the result is what it must be (scale and exposure invariance, the same
edit as the clean scene) within a stated tolerance, and that the report counts what was guarded.
The extreme scenes that need Cycles as the oracle (a lamp 10^4 times brighter, near-black and
near-white floors, the poles, a grazing floor) are in `test_removal_groundtruth.py`.
"""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from addon.light.formfactor import point_to_triangle
from addon.pipeline import remove_object
from tests.engine import tiny_room


@pytest.fixture(scope="module")
def tiny():
    return tiny_room.scene_data(64, 32)


@pytest.fixture(scope="module")
def reference(tiny):
    return remove_object(tiny, "Box", quality="draft")


def _close(a: np.ndarray, b: np.ndarray, tolerance: float) -> float:
    """Largest deviation relative to the largest change; asserts it is within `tolerance`."""
    assert np.isfinite(a).all() and np.isfinite(b).all()
    deviation = float(np.abs(a - b).max() / np.abs(b).max())
    assert deviation <= tolerance, f"deviation {deviation:.2e} of the largest change"
    return deviation


@pytest.mark.parametrize("scale", [0.01, 100.0])
def test_a_doll_house_and_a_hall_get_the_same_edit(tiny, reference, scale):
    # Radiance does not depend on the unit: a room at 1 cm or 100 m scale must give the same edit.
    scaled = replace(tiny, triangles=tiny.triangles * scale, center=tiny.center * scale)
    result = remove_object(scaled, "Box", quality="draft")
    _close(result.difference, reference.difference, 1e-3)


@pytest.mark.parametrize("exposure", [1e-3, 1e6])
def test_the_edit_scales_with_the_exposure(tiny, reference, exposure):
    # HDR values up to 10^6 (a sun in the panorama) or tiny ones: removal is linear in radiance.
    exposed = replace(tiny, hdri=(tiny.hdri * exposure).astype(np.float32))
    result = remove_object(exposed, "Box", quality="draft")
    _close(result.difference / exposure, reference.difference, 1e-3)


def test_negative_pixels_are_clamped_counted_and_kept(tiny, reference):
    hdri = tiny.hdri.copy()
    broken = (slice(12, 15), slice(0, 3))  # a patch of wall behind the probe, far from the box
    hdri[broken] = -0.5
    result = remove_object(replace(tiny, hdri=hdri), "Box", quality="draft")
    assert result.report["guards"]["negative_input_pixels_clamped"] == 9
    assert np.isfinite(result.difference).all()
    # Pixels it could not use are passed through unchanged; the rest is edited as before, up to
    # the light those 9 black pixels no longer give their patch of wall.
    assert (result.difference[broken] == 0).all() and (result.edited[broken] == -0.5).all()
    _close(result.difference, reference.difference, 0.1)


def test_degenerate_and_sliver_triangles_change_nothing(tiny, reference):
    room = tiny.object_names.index("Room")
    base = tiny.triangles[tiny.tri_object == room][:10]
    degenerate = base.copy()
    degenerate[:, 2] = degenerate[:, 1]  # two corners in one place: zero area
    sliver = base.copy()
    sliver[:, 2] = sliver[:, 1] + 1e-9 * (sliver[:, 2] - sliver[:, 1])  # 1e-9 of the width
    triangles = np.concatenate([tiny.triangles, degenerate, sliver])
    owners = np.concatenate([tiny.tri_object, np.full(20, room, dtype=tiny.tri_object.dtype)])
    result = remove_object(replace(tiny, triangles=triangles, tri_object=owners), "Box", quality="draft")
    assert result.report["guards"]["degenerate_triangles_dropped"] >= 10
    _close(result.difference, reference.difference, 1e-3)


def test_a_black_world_gives_a_zero_edit_and_says_why(tiny):
    # Irradiance zero everywhere: every ratio is guarded, nothing is divided by zero.
    result = remove_object(replace(tiny, hdri=np.zeros_like(tiny.hdri)), "Box", quality="draft")
    assert np.isfinite(result.difference).all()
    assert np.abs(result.difference).max() == 0.0
    assert result.report["guards"]["irradiance_near_zero_patches"] > 0


@pytest.mark.parametrize("offset", [2e-9, 1e-6, 1e-4])
def test_a_receiver_in_the_corner_of_two_walls_stays_finite(offset):
    # The point sits just off the edge where floor and wall meet; the wall touches it along
    # that edge. Its form factor stays finite, above a quarter (the wall is twice as wide as
    # high) and at most one half (an infinite wall). Closer than the horizon clip's 1e-9 m the
    # point counts as in the wall's plane, which it sees edge-on (zero); receivers are sampled
    # inside faces, far further from any edge than that.
    wall = np.array([[[0.0, -1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 1.0]],
                     [[0.0, -1.0, 0.0], [0.0, 1.0, 1.0], [0.0, -1.0, 1.0]]])
    corner = np.array([[offset, 0.0, 0.0]])
    f = point_to_triangle(corner, np.array([[0.0, 0.0, 1.0]]), wall).sum()
    assert np.isfinite(f) and 0.25 < f <= 0.5
