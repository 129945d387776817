"""Small copies: the preview size, area averages and interpolation, and the cache of a file's copy."""
from __future__ import annotations

import os

import numpy as np
import pytest

from addon.io.exr import write_exr
from addon.run import small_copy


def test_the_preview_is_at_most_the_preview_width_and_keeps_the_aspect():
    assert small_copy.preview_shape(8192, 16384) == (512, 1024)
    assert small_copy.preview_shape(2000, 4000) == (512, 1024)
    assert small_copy.preview_shape(256, 512) == (256, 512)
    assert small_copy.preview_shape(300, 1000, limit=500) == (150, 500)


@pytest.mark.parametrize("shape", [(8, 16), (10, 7), (11, 23)])
def test_shrinking_averages_the_area_each_pixel_covers(shape):
    rng = np.random.default_rng(1)
    image = rng.random((40, 80, 3), dtype=np.float32)
    small = small_copy.resample(image, *shape)
    assert small.shape == (*shape, 3) and small.dtype == np.float32
    # Each pixel repeated shape times makes every output pixel a whole block of the copy.
    fine = np.repeat(np.repeat(image.astype(np.float64), shape[0], axis=0), shape[1], axis=1)
    expected = fine.reshape(shape[0], 40, shape[1], 80, 3).mean(axis=(1, 3))
    np.testing.assert_allclose(small, expected, rtol=1e-5)
    np.testing.assert_allclose(small_copy.resample(np.full((40, 80, 3), 2.5, np.float32), *shape), 2.5)


def test_growing_interpolates_round_the_seam_and_clamps_at_the_poles():
    seam = np.zeros((2, 4, 1), np.float32)
    seam[:, 3] = 1.0  # the last column, next to the first round the seam
    np.testing.assert_allclose(small_copy.resample(seam, 4, 8)[:, 0, 0], 0.25)
    poles = np.zeros((2, 4, 1), np.float32)
    poles[0] = 10.0
    np.testing.assert_allclose(small_copy.resample(poles, 4, 8)[:, 0, 0], [10.0, 7.5, 2.5, 0.0])
    np.testing.assert_array_equal(small_copy.resample(seam, 2, 4), seam)


def test_a_stored_copy_is_found_until_the_file_changes(tmp_path):
    path = str(tmp_path / "pano.exr")
    folder = str(tmp_path / "cache")
    write_exr(path, np.full((64, 128, 3), 0.5, np.float32))
    assert small_copy.cached(path, folder) is None
    made = small_copy.of_file(path, folder)
    found = small_copy.cached(path, folder)
    assert found is not None and found.full_shape == (64, 128)
    np.testing.assert_array_equal(found.image, made.image)
    write_exr(path, np.full((64, 128, 3), 0.25, np.float32))
    os.utime(path, ns=(1, 1))
    assert small_copy.cached(path, folder) is None
    assert small_copy.of_file(path, folder).image.max() == pytest.approx(0.25)


def test_a_copy_is_made_from_the_file_once(tmp_path, monkeypatch):
    path = str(tmp_path / "pano.exr")
    write_exr(path, np.ones((16, 32, 3), np.float32))
    reads = []
    monkeypatch.setattr(small_copy, "read_exr", lambda p: reads.append(p) or np.ones((16, 32, 3), np.float32))
    for _ in range(3):
        small_copy.of_file(path, str(tmp_path / "cache"))
    assert reads == [path]


def test_the_cache_keeps_the_newest_copies(tmp_path):
    folder = str(tmp_path / "cache")
    copy = small_copy.of_image(np.zeros((4, 8, 3), np.float32))
    paths = [str(tmp_path / f"{i}.exr") for i in range(small_copy.KEEP + 3)]
    for path in paths:
        open(path, "w").close()
        small_copy.store(path, copy, folder)
        assert small_copy.cached(path, folder) is not None
    assert len(os.listdir(folder)) == small_copy.KEEP
