"""The working resolution: the light is solved on a smaller copy of the panorama, since the
change of light is smooth except where the full-resolution stage refines it."""
from __future__ import annotations

import numpy as np

from ..geometry.resample import interpolate, resample_axis
from ..radiance import clamped_rows
from ..side_by_side import each

# Rows of the full panorama resampled at a time: a band that stays in a core's cache makes the
# passes over it (a pass over a panorama is bound by memory, not by arithmetic) twice as fast
# as one of 64 MB, and lets two bands side by side run twice as fast as one.
_BAND_BYTES = 4 << 20


def working_size(width: int, height: int, *, max_width: int) -> tuple[int, int]:
    """(width, height) the light is solved at: the panorama's own up to `max_width`."""
    if width <= max_width:
        return width, height
    return max_width, max_width // 2


def downsample(radiance: np.ndarray, width: int, height: int) -> np.ndarray:
    """(height, width, 3) float64 area average of an (H, W, 3) panorama, negative radiance
    read as black, read in bands of rows so no float64 copy of the whole input is made."""
    rows_in, cols_in, channels = radiance.shape
    # Whole rows of output pixels per band, so the bands' averages are the whole one's.
    per_output_row = int(np.ceil(rows_in / height))
    band = max(1, _BAND_BYTES // (cols_in * channels * 8 * per_output_row)) * per_output_row
    if rows_in % height:
        columns = np.empty((rows_in, width, channels))
        for start in range(0, rows_in, band):
            rows = np.maximum(radiance[start:start + band].astype(np.float64), 0.0)
            columns[start:start + band] = resample_axis(rows, width, axis=1)
        return resample_axis(columns, height, axis=0)
    out = np.empty((height, width, channels))
    step = rows_in // height

    def average(start: int) -> None:
        out[start // step:(start + band) // step] = _block_means(clamped_rows(radiance, start, start + band), step)

    each(average, range(0, rows_in, band))  # bands side by side, each writing output rows of its own
    return out


def _block_means(rows: np.ndarray, step: int) -> np.ndarray:
    """(h / step, w / step, C) float64 means of the step x step blocks of (h, w, C) `rows`: each
    row's columns, then the rows, summed one after the other in float64 as resample_axis's
    means sum them (so bit for bit the same), but from strided views of the float32 band
    instead of a float64 copy of it (a third of the time at 8K)."""
    cols = rows[:, 0::step].astype(np.float64)
    for j in range(1, step):
        cols += rows[:, j::step]
    cols /= step
    blocks = cols[0::step].copy()
    for i in range(1, step):
        blocks += cols[i::step]
    blocks /= step
    return blocks


def upsample(image: np.ndarray, height: int, width: int, *, add_to: np.ndarray | None = None) -> np.ndarray:
    """A working-resolution (h, w, C) image or (h, w) mask at (height, width): images
    interpolated (float32, in bands of rows; with `add_to`, added into that array instead of
    a new one), masks by the nearest pixel."""
    h, w = image.shape[:2]
    if image.dtype == bool:
        rows = np.clip(np.round((np.arange(height) + 0.5) * (h / height) - 0.5).astype(np.int64), 0, h - 1)
        cols = np.mod(np.round((np.arange(width) + 0.5) * (w / width) - 0.5).astype(np.int64), w)
        return image[rows][:, cols]
    wide = resample_axis(image.astype(np.float32), width, axis=1)
    out = np.zeros((height, width, *image.shape[2:]), dtype=np.float32) if add_to is None else add_to
    band = max(1, _BAND_BYTES // (wide[0].nbytes * 4))
    for start in range(0, height, band):
        rows = np.arange(start, min(start + band, height))
        out[start:start + band] += interpolate(wide, height, axis=0, samples=rows)
    return out
