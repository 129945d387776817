"""Several removals composed: each on the panorama plus the earlier differences, the earlier
objects gone from the geometry, the result the sum of the differences."""
from __future__ import annotations

import numpy as np

from addon.composition import on_earlier, remove_in_order, without_objects
from addon.removal import RemovalResult
from tests.engine import tiny_room


def test_objects_left_out_are_gone_and_the_rest_numbered_as_the_reader_numbers_them():
    scene = tiny_room.scene_data(32, 16)  # Box, Floor, Lamp, Room
    without = without_objects(scene, ["Box", "Lamp"])
    assert without.object_names == ["Floor", "Room"]
    for index, name in enumerate(without.object_names):
        np.testing.assert_array_equal(without.triangles[without.tri_object == index],
                                      scene.triangles[scene.tri_object == scene.object_index(name)])
    assert without.tri_object.dtype == scene.tri_object.dtype
    assert len(without.triangles) == len(without.tri_object)
    assert without_objects(scene, ["Nothing"]) is scene


def test_the_differences_are_added_in_turn_and_the_callers_panorama_is_left_alone():
    scene = tiny_room.scene_data(32, 16)
    before = scene.hdri.copy()
    first, second = np.full_like(before, 0.25), np.full_like(before, 0.5)
    composed = on_earlier(scene, [first, second], ["Box"])
    np.testing.assert_array_equal(composed.hdri, (before + first) + second)
    np.testing.assert_array_equal(scene.hdri, before)
    assert "Box" not in composed.object_names and composed.hdri.dtype == np.float32
    own = on_earlier(scene, [first], [], own=True)
    assert own.hdri is scene.hdri  # a panorama read for this run takes the differences itself
    np.testing.assert_array_equal(scene.hdri, before + first)


def test_objects_are_removed_in_order_each_from_what_the_ones_before_left():
    scene = tiny_room.scene_data(32, 16)
    calls = []

    def remove(step, name):
        calls.append((name, step.hdri.copy(), list(step.object_names)))
        hidden = np.zeros(step.hdri.shape[:2], bool)
        hidden[0, len(calls)] = True
        return RemovalResult(difference=np.full_like(step.hdri, 0.125 * len(calls)), hidden_mask=hidden,
                             report={"seconds": {"local": 1.0}, "warnings": [f"w{len(calls)}"], "hidden_pixels": 1},
                             hdri=step.hdri)

    result = remove_in_order(scene, ["Box", "Lamp"], remove)
    (first, first_hdri, first_names), (second, second_hdri, second_names) = calls
    assert (first, second) == ("Box", "Lamp")
    np.testing.assert_array_equal(first_hdri, scene.hdri)
    np.testing.assert_array_equal(second_hdri, scene.hdri + np.float32(0.125))
    assert "Box" in first_names and "Box" not in second_names and "Lamp" in second_names
    np.testing.assert_array_equal(result.difference, np.full_like(scene.hdri, 0.375))
    assert result.hidden_mask.sum() == 2 and result.hdri is scene.hdri
    assert result.report["objects"] == ["Box", "Lamp"] and len(result.report["removals"]) == 2
    assert result.report["seconds"] == {"local": 2.0} and result.report["hidden_pixels"] == 2
    assert result.report["warnings"] == ["Box: w1", "Lamp: w2"]
    # One object: the removal's own result, untouched.
    single = remove_in_order(scene, ["Box"], remove)
    assert "objects" not in single.report
