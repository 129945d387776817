"""The engine's front door refuses input it cannot work with, one line saying what."""
from __future__ import annotations

import numpy as np
import pytest

from addon import pipeline
from addon.errors import DimredError
from addon.scene import SceneData


def _scene(hdri: np.ndarray | None, center=(0.0, 0.0, 1.0), path: str = "") -> SceneData:
    return SceneData(hdri=hdri, rotation=np.eye(3), center=np.array(center), triangles=np.zeros((0, 3, 3)),
                     tri_object=np.zeros(0, int), object_names=[], hdri_path=path)


def _refused(scene: SceneData) -> str:
    with pytest.raises(DimredError) as refused:
        pipeline.validate(scene)
    return str(refused.value)


def test_a_clean_panorama_passes():
    pipeline.validate(_scene(np.ones((8, 16, 3), np.float32)))


@pytest.mark.parametrize(
    "hdri, expected",
    [
        (None, "the panorama's pixels were not read"),
        (np.ones((8, 16), np.float32), "must be an RGB panorama, got an array of shape (8, 16)"),
        (np.ones((8, 10, 3), np.float32), "the world image is 10x8: a lat-long panorama is twice as wide as high"),
    ],
)
def test_not_a_panorama(hdri, expected):
    assert expected in _refused(_scene(hdri))


def test_non_finite_pixels_are_counted_per_pixel():
    hdri = np.ones((64, 128, 3), np.float32)
    hdri[0, 0] = np.nan  # three channels, one pixel
    hdri[63, 127, 1] = np.inf
    hdri[30, 5, 2] = -np.inf
    message = _refused(_scene(hdri, path="/p/room.exr"))
    assert message == "/p/room.exr contains 3 pixels with NaN or infinite values"


def test_the_probe_centre_must_be_a_point():
    assert _refused(_scene(np.ones((8, 16, 3), np.float32), center=(0.0, np.nan, 1.0))) == (
        "the probe centre is not a finite point"
    )
