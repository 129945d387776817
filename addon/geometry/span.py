"""The rectangle of panorama pixels a mask occupies, with its columns wrapping around the seam."""
from __future__ import annotations

import numpy as np


def pixel_span(mask: np.ndarray, pad: int) -> tuple[int, int, int, int]:
    """(first row, end row, first column, columns) of the pixels of `mask` (h, w) and `pad`
    more around; the columns wrap (all of them when the span would close the circle)."""
    h, w = mask.shape
    rows = np.flatnonzero(mask.any(axis=1))
    col0, cols = column_span(mask.any(axis=0))
    col0, cols = (0, w) if cols + 2 * pad >= w else (col0 - pad, cols + 2 * pad)
    return max(0, int(rows[0]) - pad), min(h, int(rows[-1]) + 1 + pad), col0, cols


def column_span(columns: np.ndarray) -> tuple[int, int]:
    """(first, count) of the shortest circular run of columns holding every True one."""
    w = len(columns)
    on = np.flatnonzero(columns)
    gaps = np.diff(np.concatenate([on, on[:1] + w]))
    widest = int(gaps.argmax())
    first = int(on[(widest + 1) % len(on)])
    return first, w - int(gaps[widest]) + 1
