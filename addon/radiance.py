"""The panorama's radiance as the engine reads it, a band of rows at a time.

Negative radiance is not light (a bad merge or a denoiser's ringing): the engine reads it as
black, through `clamped_rows`. Checks over the whole panorama scan it band by band, so that
none builds a full-size temporary beside a 16384 x 8192 image.
"""
from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

_BAND_PIXELS = 1 << 21  # pixels per band: a float32 RGB band is 24 MB


def row_bands(height: int, width: int) -> Iterator[tuple[int, int]]:
    """(start, stop) of consecutive bands of rows covering `height` rows `width` pixels wide."""
    rows = max(1, _BAND_PIXELS // max(1, width))
    for start in range(0, height, rows):
        yield start, min(start + rows, height)


def clamped_rows(hdri: np.ndarray, start: int, stop: int) -> np.ndarray:
    """Rows start:stop of the (H, W, 3) panorama with negative radiance read as black, in the
    panorama's dtype (a new array)."""
    return np.maximum(hdri[start:stop], 0)


def negative_pixels(hdri: np.ndarray) -> int:
    """How many pixels of the (H, W, 3) panorama have a negative channel."""
    return _pixels_where(hdri, lambda band: band.min() < 0, lambda band: (band < 0).any(axis=2))


def non_finite_pixels(hdri: np.ndarray) -> int:
    """How many pixels of the (H, W, 3) panorama have a NaN or infinite channel."""
    return _pixels_where(hdri, lambda band: not all_finite(band), lambda band: ~np.isfinite(band).all(axis=2))


def all_finite(values: np.ndarray) -> bool:
    """Whether every value of a float array is finite: its minimum and maximum are NaN or
    infinite exactly when some value is (two reductions, ten times faster than np.isfinite's
    array of flags on a panorama)."""
    return bool(np.isfinite(values.min()) and np.isfinite(values.max()))


def _pixels_where(hdri: np.ndarray, some: Callable[[np.ndarray], bool], test: Callable[[np.ndarray], np.ndarray]
                  ) -> int:
    """How many pixels `test` (a band -> a bool per pixel) finds, over all bands; a band for
    which `some` (one reduction) says there are none is not tested pixel by pixel."""
    bands = (hdri[start:stop] for start, stop in row_bands(*hdri.shape[:2]))
    return sum(int(np.count_nonzero(test(band))) for band in bands if some(band))


#: Mantissa bits the difference keeps (of float32's 23): a relative precision of 6e-5, eight
#: times finer than a half-float panorama's own. The bits below are noise of the photograph
#: times the light's ratio, which the file's lossless compression cannot shrink: at 8192 x 4096
#: the difference's EXR was 222 MB and took 3.7 s of CPU to write, rounded 108 MB and 1.8 s.
STORED_MANTISSA_BITS = 13


def round_to_stored_precision(values: np.ndarray) -> np.ndarray:
    """Round float32 `values` in place to STORED_MANTISSA_BITS, to nearest (ties away from
    zero), band by band; returns them. Non-finite values stay non-finite."""
    if values.dtype != np.float32 or not values.flags.c_contiguous:
        raise ValueError(f"expects a contiguous float32 array, got {values.dtype}")
    dropped = 23 - STORED_MANTISSA_BITS
    half, mask = np.uint32(1 << (dropped - 1)), np.uint32((0xFFFFFFFF << dropped) & 0xFFFFFFFF)
    bits = values.reshape(-1).view(np.uint32)
    for start in range(0, len(bits), _BAND_PIXELS):
        band = bits[start:start + _BAND_PIXELS]
        # A carry out of the mantissa raises the exponent: still the nearest value.
        band += half
        band &= mask
    return values
