"""The working resolution: its size per preset, the area average down and the interpolation up."""
from __future__ import annotations

import numpy as np

from addon.quality import PRESETS
from addon.removal import working
from addon.removal.working import downsample, upsample, working_size


def test_working_size_keeps_small_panoramas_and_caps_large_ones():
    assert working_size(1024, 512, max_width=1024) == (1024, 512)
    assert working_size(8192, 4096, max_width=1024) == (1024, 512)
    assert working_size(6720, 3360, max_width=2048) == (2048, 1024)
    assert PRESETS["final"].working_width > PRESETS["balanced"].working_width


def test_downsample_is_the_area_mean_and_keeps_the_total(monkeypatch):
    rng = np.random.default_rng(0)
    image = rng.random((64, 128, 3)).astype(np.float32)
    blocks = image.reshape(16, 4, 32, 4, 3).mean(axis=(1, 3))
    assert np.allclose(downsample(image, 32, 16), blocks, atol=1e-6)
    # A fractional factor (6720 -> 2048 is 3.28) weights the pixels a bin shares.
    assert abs(downsample(image, 48, 24).mean() - image.mean()) < 1e-6
    monkeypatch.setattr(working, "_BAND_BYTES", 128 * 3 * 8 * 5)  # bands of 5 rows
    assert np.allclose(downsample(image, 48, 24), downsample(image.astype(np.float64), 48, 24))
    assert np.allclose(downsample(image, 32, 16), blocks, atol=1e-6)


def test_downsample_reads_negative_radiance_as_black():
    image = np.ones((8, 16, 3), dtype=np.float32)
    image[0, 0] = -100.0
    assert downsample(image, 8, 4).min() >= 0.0


def test_upsample_interpolates_images_and_repeats_masks():
    small = np.zeros((4, 8, 1), dtype=np.float32)
    small[:, :4] = 1.0
    big = upsample(small, 16, 32)
    assert big.shape == (16, 32, 1) and big.dtype == np.float32
    assert big[:, 2:14].min() == 1.0 and big[:, 18:30].max() == 0.0
    assert 0.0 < big[5, 15, 0] < 1.0  # between the two halves
    mask = upsample(small[..., 0] > 0, 16, 32)
    assert mask.dtype == bool and mask[:, :16].all() and not mask[:, 16:].any()
