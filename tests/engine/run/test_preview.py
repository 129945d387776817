"""Previews over what the world shows: the quick fill at once, the engine's difference after."""
from __future__ import annotations

import numpy as np

from addon.geometry.mesh import to_probe_frame
from addon.run.preview import Preview, Previews
from tests.engine import tiny_room


def _images(preview: Preview) -> tuple[np.ndarray, np.ndarray]:
    """(colour, mask) of a preview, top row first, as the world samples them."""
    def unflip(buffer: np.ndarray) -> np.ndarray:
        return buffer.reshape(preview.height, preview.width, 4)[::-1, :, :3]

    return unflip(preview.color), unflip(preview.mask)[..., 0]


def _box_scene(width: int):
    scene = tiny_room.scene_data(width, width // 2)
    mine = scene.tri_object == scene.object_index("Box")
    return scene, to_probe_frame(scene.triangles[mine], scene.center, scene.rotation)


def test_the_quick_preview_replaces_the_object_and_adds_nothing_elsewhere():
    scene, box = _box_scene(256)
    previews, first = Previews.quick(scene.hdri, box)
    color, mask = _images(first)
    assert (first.width, first.height) == (256, 128)
    far = mask == 0
    assert far.mean() > 0.9 and (color[far] == 0).all()
    inside = mask == 1
    assert inside.sum() > 50
    # The box (red) is replaced by the grey of the room around it.
    assert np.median(color[inside, 0] / color[inside, 1]) < 1.2
    np.testing.assert_array_equal(previews.mask, mask)


def test_an_object_the_scene_lacks_has_no_quick_preview_and_an_empty_mask():
    scene, _ = _box_scene(64)
    previews, first = Previews.quick(scene.hdri, None)
    assert first is None and not previews.mask.any()


def test_the_world_shows_the_panorama_plus_the_difference_at_preview_size():
    scene, box = _box_scene(128)
    rng = np.random.default_rng(2)
    difference = rng.normal(0.0, 0.1, (64, 128, 3)).astype(np.float32)
    previous = rng.normal(0.0, 0.1, (64, 128, 3)).astype(np.float32)
    for earlier in (None, previous):
        previews, _ = Previews.quick(scene.hdri, box)
        if earlier is not None:
            previews = Previews(previews.panorama, previews.mask, earlier)
        color, mask = _images(previews.of_difference(difference))
        # What the world showed before: the panorama with this object's earlier difference.
        before = scene.hdri if earlier is None else scene.hdri + earlier
        np.testing.assert_allclose(before * (1.0 - mask[..., None]) + color, scene.hdri + difference, atol=1e-5)


def test_a_difference_of_any_size_is_resampled_to_the_preview():
    scene, box = _box_scene(64)
    previews, _ = Previews.quick(scene.hdri, box)
    for shape in ((128, 256, 3), (16, 32, 3)):
        preview = previews.of_difference(np.zeros(shape, np.float32))
        assert (preview.width, preview.height) == (64, 32)
        assert preview.color.shape == preview.mask.shape == (64 * 32 * 4,)
