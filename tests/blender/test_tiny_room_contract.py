"""The engine tests' tiny room (`tests/engine/tiny_room.py`, arrays only) is what the reader
reads from the same room built in Blender (`tiny_scene.build_scene`): the engine tests run
without Blender, and this contract is what keeps their input the scene a user would have."""
from __future__ import annotations

import numpy as np
import pytest

from tests.blender import tiny_scene
from tests.engine import tiny_room


@pytest.mark.parametrize("size", [(64, 32), (128, 64)])
def test_the_array_room_is_the_room_the_reader_reads_from_blender(fresh_blender, tmp_path, size):
    width, height = size
    read = tiny_scene.scene_data(tmp_path, width, height)
    built = tiny_room.scene_data(width, height)

    assert read.object_names == built.object_names == ["Box", "Floor", "Lamp", "Room"]
    np.testing.assert_array_equal(read.tri_object, built.tri_object)
    assert read.triangles.dtype == built.triangles.dtype == np.float64
    # The same triangles in the same order, bit for bit (both round the vertices to float32): the
    # order decides the engine's patch and sender order, so engine results are the same too.
    np.testing.assert_array_equal(read.triangles, built.triangles)
    np.testing.assert_array_equal(read.center, built.center)
    np.testing.assert_array_equal(read.rotation, built.rotation)
    assert read.hdri.dtype == built.hdri.dtype == np.float32
    np.testing.assert_array_equal(read.hdri, built.hdri)
