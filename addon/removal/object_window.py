"""The part of the full-resolution panorama around the removed object: which pixels show it,
what they reveal once it is gone, and the surfaces the fill's exemplar is read from."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import latlong
from ..geometry.mesh import Geometry
from ..geometry.planeraster import Frame
from ..geometry.raycast import trace_panorama
from ..geometry.span import pixel_span
from ..segmentation.seen import SeenObject
from ..side_by_side import each
from .target import Target
from .working_maps import WorkingMaps, nearest_working, surfaces_seen

_PAD = 4  # working pixels the window reaches past what it must hold
_MAX_PIXELS = 2 << 20  # the largest window (its arrays and the fill's maps take ~120 bytes a pixel)
_RING = 3  # full-resolution pixels beside the object always get their own light
_BLOCK_PIXELS = 1 << 17  # pixels looked up at a time (bounds the candidates' temporaries)


@dataclass(frozen=True)
class ObjectWindow:
    """(h, w) arrays over `frame`: the full-resolution pixels around the object."""

    frame: Frame
    hidden: np.ndarray  # bool: filled (the object as photographed and its silhouette, one pixel wide)
    kept: np.ndarray  # bool: the proxy is the first hit but the photograph shows no object (left as it is)
    ring: np.ndarray  # bool: not hidden, within a few pixels of it
    on_object: np.ndarray  # bool: the object is the first hit
    tri: np.ndarray  # int32: what the pixel sees without the object (-1 for nothing)
    distance: np.ndarray  # float32: its distance (inf for nothing)
    bary: np.ndarray  # (h, w, 2) float32 barycentric weights of vertices 1 and 2 there
    object_distance: np.ndarray  # float32: distance of the object's first hit (inf where none)
    object_tri: np.ndarray  # int32: the object's triangle hit (-1 for none)

    def holds(self, rows: np.ndarray, cols: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Panorama pixels -> this window's (row, column) and whether it holds them."""
        return self.frame.locate(rows, cols, self.hidden.shape)


def object_window(geo: Geometry, target: Target, hidden_working: np.ndarray, cover: np.ndarray | None,
                  full: tuple[int, int], maps: WorkingMaps, seen: SeenObject | None = None) -> ObjectWindow | None:
    """The window around the pixels the working panorama hides (`hidden_working`, (h, w)) and
    the directions (N, 3) it must `cover` as well (the fill's exemplar), at most
    _MAX_PIXELS large, traced at the full resolution `full` (height, width); None when
    nothing is hidden. The pixels `seen` shows the object in are filled (default: the proxy's)."""
    if not hidden_working.any():
        return None
    height, width = full
    h, w = hidden_working.shape
    wanted = hidden_working.copy()
    if cover is not None and len(cover):
        wanted[latlong.uv_to_pixel(*latlong.direction_to_uv(cover), w, h)] = True
    must = pixel_span(hidden_working, _PAD)
    want = pixel_span(wanted, _PAD)
    # The wanted columns as a run that starts left of the object's own (they hold them).
    left = (must[2] - want[2]) % w if want[3] < w else (w - must[3]) // 2
    want = (want[0], want[1], must[2] - left, want[3])
    scale = height / h
    # Too large a window is cut back towards the object (the exemplar loses its far cells);
    # the object and its surroundings always stay in.
    for t in np.linspace(1.0, 0.0, 21):
        r0, r1, col0, cols = (round(m + t * (x - m)) for m, x in zip(must, want, strict=True))
        if (r1 - r0) * cols * scale * scale <= _MAX_PIXELS:
            break
    row_start, row_stop = int(np.floor(r0 * scale)), int(np.ceil(r1 * scale))
    col_start = int(np.floor(col0 * scale)) % width
    ncols = width if cols == w else min(width, int(np.ceil(cols * scale)))
    window = (row_start, row_stop - row_start, col_start, ncols)
    on = np.flatnonzero(geo.tri_object == target.index)
    obj = trace_panorama(geo.triangles[on], width, height, window=window, projection=geo.projection.take(on))
    # float32 and int32: a window of millions of pixels is the largest thing the run holds
    # besides the panorama and its difference; a metre in float32 is exact to a micron.
    object_distance = np.where(obj.tri >= 0, obj.distance, np.inf).astype(np.float32)
    object_tri = np.where(obj.tri >= 0, on[np.maximum(obj.tri, 0)], -1).astype(np.int32)
    directions = obj.directions
    shape = obj.tri.shape
    del obj
    tri = np.empty(shape, dtype=np.int32)
    distance = np.empty(shape, dtype=np.float32)
    bary = np.empty((*shape, 2), dtype=np.float32)
    cols_full = np.mod(col_start + np.arange(ncols), width)
    block = max(1, _BLOCK_PIXELS // ncols)

    def look_up(start: int) -> None:
        """What the block of rows from `start` sees, written into its rows."""
        rows_b = row_start + np.arange(start, min(start + block, shape[0]))
        nearest = nearest_working(rows_b[:, None], cols_full[None, :], full, maps).ravel()
        found = surfaces_seen(directions[start:start + len(rows_b)].reshape(-1, 3), nearest, geo, maps)
        tri[start:start + len(rows_b)] = found.tri.reshape(-1, ncols)
        distance[start:start + len(rows_b)] = found.distance.reshape(-1, ncols)
        bary[start:start + len(rows_b)] = found.bary.reshape(-1, ncols, 2)

    each(look_up, range(0, shape[0], block))  # blocks side by side, each writing rows of its own
    on_object = object_distance < distance
    frame = Frame(row_start, col_start, height, width)
    hidden = latlong.dilate(on_object if seen is None else seen.in_frame(frame, shape), 1)
    kept = on_object & ~hidden
    ring = latlong.dilate(hidden, _RING) & ~hidden & ~kept
    return ObjectWindow(frame=frame, hidden=hidden, kept=kept, ring=ring, on_object=on_object, tri=tri,
                        distance=distance, bary=bary, object_distance=object_distance, object_tri=object_tri)
