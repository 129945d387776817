"""A wall's hole continued column by column from the wall seen above and below it.

What stands on a wall runs vertically: a door and its frame, the edge between a pale wall and
a dark panel, a curtain's folds, a corner. An object in front of a wall hides the wall's lower
part, so the edges that reach the hole's border from above are the ones to continue down
through it, and each column of the hole shows what its own column shows beside the hole. Drawn
from the "material around the hole" (`material`), the fill instead mixes the pale wall, the
door and the floor line into one flat patch: on the photo-textured hotel room (a box before a
door beside a white wall) the door was taken for clutter and repainted with the wall's colour.

Each column is interpolated between the wall seen at its two ends (one end only where the
hole reaches the wall's edge, as it does at the floor), and it takes the detail along the
column of the wall beside the hole, mirrored about the hole's border so that the copy meets it
without a step.
"""
from __future__ import annotations

import numpy as np

from .lines import along_mean, interpolate_lines
from .structure import Filled
from .texture import CancelFn, ProgressFn, SynthesisParams, fill_with_sources

_COLUMN = 0  # the raster axis along a wall's verticals (`planeraster.is_wall`)
# cells averaged at each end of a column: the border cell alone would carry its noise down the column
_ENDS = 6


def column_sources(known: np.ndarray, hole: np.ndarray) -> np.ndarray:
    """(H, W, 2) for each `hole` pixel the known pixel of its column whose detail it takes: the
    nearer known end of the hole along the column, then away from the hole by the distance
    past that end, reflected back and forth within the run of known pixels there; -1 where
    the column holds no known pixel and off the hole."""
    h, w = known.shape
    row = np.broadcast_to(np.arange(h)[:, None], (h, w))
    before = np.maximum.accumulate(np.where(known, row, -1), axis=0)  # the nearest known row at or before
    after = np.minimum.accumulate(np.where(known, row, h)[::-1], axis=0)[::-1]
    # the far end of the known run each known pixel belongs to
    run_lo = np.maximum.accumulate(np.where(known, -1, row), axis=0) + 1
    run_hi = np.minimum.accumulate(np.where(known, h, row)[::-1], axis=0)[::-1] - 1
    col = np.broadcast_to(np.arange(w), (h, w))
    has_before, has_after = before >= 0, after < h
    from_before = has_before & (~has_after | (row - before <= after - row))
    end = np.where(from_before, before, after)
    end_c = np.clip(end, 0, h - 1)
    length = np.where(from_before, end_c - run_lo[end_c, col] + 1, run_hi[end_c, col] - end_c + 1)
    past = np.abs(row - end) - 1
    back = np.mod(past, 2 * np.maximum(length, 1))
    back = np.where(back < length, back, 2 * length - 1 - back)
    source_row = np.where(from_before, end - back, end + back)
    ok = hole & (has_before | has_after)
    out = np.full((h, w, 2), -1, np.int64)
    out[ok, 0] = source_row[ok]
    out[ok, 1] = col[ok]
    return out


def fill_columns(image: np.ndarray, known: np.ndarray, hole: np.ndarray) -> Filled:
    """`image` (H, W, C) of a wall's raster with its `hole` pixels continued along the columns
    (axis 0): interpolated between the means of the known pixels at each end of the hole, plus
    the detail along the column of the pixel `column_sources` gives (its value minus the mean
    of the known pixels around it along the column). `sources` is that pixel; a hole pixel
    whose column holds no known pixel is left as it is, with source -1."""
    known = np.asarray(known, bool) & ~hole
    lines = interpolate_lines(image, known, axis=_COLUMN, ends=_ENDS)
    sources = column_sources(known, hole)
    filled = sources[..., 0] >= 0
    r, c = sources[filled, 0], sources[filled, 1]
    local = along_mean(image, known, axis=_COLUMN, radius=_ENDS)
    out = np.array(image, np.float32, copy=True)
    out[filled] = lines.values[filled] + image[r, c] - local[r, c]
    return Filled(out, sources, None)


def fill_wall(image: np.ndarray, known: np.ndarray, hole: np.ndarray, params: SynthesisParams, *, seed: int = 0,
              progress: ProgressFn | None = None, cancel: CancelFn | None = None) -> Filled:
    """`image` (H, W, C) of a wall's raster with its `hole` filled: continued along the columns
    (`fill_columns`), and where a column holds nothing seen, by the order-independent synthesis
    from the wall's `known` pixels (`texture.fill_with_sources`, which raises `DimredError` on
    too little exemplar). `progress(level, preview)` gets the synthesis's levels, if it runs."""
    got = fill_columns(image, known, hole)
    rest = hole & (got.sources[..., 0] < 0)
    if not rest.any():
        return got
    out, sources = fill_with_sources(got.image, known | (hole & ~rest), rest, params, seed=seed, progress=progress,
                                     cancel=cancel)
    # the columns' pixels constrain the synthesis but are no photograph to read detail from
    copied = rest & (sources[..., 0] >= 0)
    copied[copied] = known[sources[copied, 0], sources[copied, 1]]
    return Filled(out, np.where(copied[..., None], sources, got.sources), None)
