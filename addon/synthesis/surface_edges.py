"""Where the photograph shows two proxy surfaces meeting, near the hole.

A room modelled by eye puts a wall/floor line a few pixels (at 1024x512 up to twenty) from the
photograph's. Filled by the proxy's surfaces, the part of the hole between the two lines gets
the other surface's texture (a pale band of wall on the floor), and the exemplar beside the
hole carries the other surface's pixels (a curtain's folds on the floor raster). So each edge
between two surfaces near the hole is looked for in the photograph and the pixels between the
two lines change surface.

The edge is a straight line in 3D; seen from the probe it lies on a great circle. The
candidates are the great circles near the proxy's edge: to first order an offset from it and a
slope along it (a wall or floor shifted, turned). Beside the hole, along the proxy's edge, every
candidate is scored by the colour step across it (log radiance, a band on either side), measured
segment by segment along the edge and averaged as vectors: a line that steps with one sign and
colour all along the hole wins over a desk's corner or a rug's end that steps in one segment. The
edge is continued through the hole on the great circle it lies on.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..geometry import latlong
from ..geometry.planeraster import Frame, is_wall
from ..segmentation.masks import dilate

# Search range and bands, in pixel angles (pi / panorama height) at the hole: an eye-modelled
# room's wall/floor line lies up to about 8 degrees (23 pixels at 1024x512) from the
# photograph's (the hotel room's window wall: 15-20 pixels).
_SEARCH = 24.0
_BAND = 3.0  # pixels each side of a candidate whose mean colours make its step
_BIN = 0.5  # candidate spacing
_SEGMENT = 8.0  # length of a segment along the edge
_MIN_SEGMENTS = 3  # segments with both bands seen that an edge needs
_MIN_BAND_PIXELS = 3  # pixels each band needs in a segment
_PROMINENCE = 3.0  # the best step against the median candidate's: below it the photograph shows no edge
# Below this step (log radiance, about 10 %) the two sides differ too little for the wrong
# surface's texture to show: no edge is taken, the proxy's is kept.
_MIN_STEP = 0.1
_MAX_SLOPE = 0.1  # pixels of offset per pixel along the edge: the photograph's edge turned by up to 6 degrees
# The proxy's own line is the prior: another is taken only where it steps this many times more.
# A checker's tile rows along a pale wall step 2.9 times more than the wall's edge (basic_box, an
# exact proxy); the hotel room's curtain hem and skirting 17 times more than the proxy's line.
_OVER_PROXY = 4.0
# Nor within this many pixels of it at the hole's middle: a line turned about the hole took a
# printed wall's texture for the edge on the photo-textured hotel room (an exact proxy).
_MIN_SHIFT = 2.0
_BESIDE = 0.3  # the stretch measured: the hole's along the edge and this share of it on either side
_MIN_ADJACENT = 3  # pixel pairs across which two surfaces must meet near the hole to count as an edge
# Only a floor's or a ceiling's edges (`planeraster.is_wall`: not a wall) are looked for: a
# corner between two walls is a vertical line among many in a photograph (a door's frame, a
# curtain's edge), which the search took for the corner on the photo-textured hotel room.


@dataclass(frozen=True)
class SurfacePlane:
    """A proxy surface's plane: points x with normal . x = offset (probe frame)."""

    normal: np.ndarray
    offset: float


@dataclass(frozen=True)
class SurfaceEdge:
    """Two surfaces' shared line: `first` on the positive side of the great circle of normal
    `proxy` (the proxy's edge, through the vanishing points `axis` and its point nearest the
    probe `foot`), `second` on the other. A direction's offset from the proxy's edge is its angle
    about `axis` in pixels at the hole (`scale` per radian); the photograph's edge lies at
    offset `shift` + `slope` t, t the position along the edge (`_along`): to first order the
    great circles near the proxy's. Pixels change surface only along the stretch `span` (radians
    along the edge from `foot`); `found` False: the photograph showed no edge, none change."""

    first: int
    second: int
    axis: np.ndarray
    foot: np.ndarray
    proxy: np.ndarray
    scale: float
    middle: float
    shift: float
    slope: float
    span: tuple[float, float]
    found: bool

    def _coordinates(self, directions: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(N,) each direction's offset from the proxy's edge and from the photograph's (pixels,
        positive toward `first`), its angle along the edge, and whether it faces the edge (not
        its antipode)."""
        x, y, z = directions @ self.proxy, directions @ self.foot, directions @ self.axis
        offset = np.arctan2(x, y) * self.scale
        along = np.arctan2(z, np.hypot(x, y))
        photo = offset - self.shift - self.slope * _along(along, self.middle, self.scale)
        return offset, photo, along, y > 0

    def moved(self, directions: np.ndarray) -> np.ndarray:
        """(N,) bool: the unit `directions` (N, 3) between the proxy's edge and the photograph's."""
        if not self.found:
            return np.zeros(len(directions), dtype=bool)
        offset, photo, along, facing = self._coordinates(directions)
        return facing & ((offset > 0) != (photo > 0)) & (along >= self.span[0]) & (along <= self.span[1])

    def surface_of(self, directions: np.ndarray) -> np.ndarray:
        """(N,) the surface the photograph's edge puts each of `directions` on (its side of it)."""
        _, photo, _, _ = self._coordinates(directions)
        return np.where(photo > 0, self.first, self.second)

    def across(self, directions: np.ndarray, pixels: float) -> np.ndarray:
        """(N, 3) unit directions at the same place along the edge, `pixels` past the proxy's edge
        on the side of the surface the photograph puts each on: where that surface's own light is
        found beside the proxy's corner."""
        x, y, z = directions @ self.proxy, directions @ self.foot, directions @ self.axis
        radius = np.hypot(x, y)
        angle = np.where(self.surface_of(directions) == self.first, pixels, -pixels) / self.scale
        out = radius[:, None] * (np.cos(angle)[:, None] * self.foot + np.sin(angle)[:, None] * self.proxy)
        return out + z[:, None] * self.axis

    def describe(self, names: dict[int, str]) -> dict:
        """The report's entry: the two surfaces and the shift in pixels at the hole, or why it was kept."""
        entry: dict = {"surfaces": [str(names.get(s, s)) for s in (self.first, self.second)]}
        if self.found:
            entry["shift_px"] = round(self.shift, 1)
            entry["slope"] = round(self.slope, 3)
        else:
            entry["kept"] = "no edge found"
        return entry


def _along(along: np.ndarray, middle: float, scale: float) -> np.ndarray:
    """Position along the edge in pixels from the hole's middle, linear in tan(along): the
    offsets of the great circles near the proxy's are linear in it (to first order)."""
    return (np.tan(along) - np.tan(middle)) * np.cos(middle) ** 2 * scale


@dataclass(frozen=True)
class SurfaceEdges:
    """The edges found near the hole; `assign` moves pixels to the surface the photograph shows."""

    edges: tuple[SurfaceEdge, ...]

    def assign(self, directions: np.ndarray, surface: np.ndarray) -> np.ndarray:
        """(N,) `surface` (N,) of unit `directions` (N, 3), those between an edge's proxy line
        and photograph line (and on one of its two surfaces) moved to the photograph's side."""
        out = np.array(surface, copy=True)
        for edge in self.edges:
            move = edge.moved(directions) & ((surface == edge.first) | (surface == edge.second))
            out[move] = edge.surface_of(directions[move])
        return out

    def across(self, directions: np.ndarray, surface: np.ndarray, angle: float) -> np.ndarray:
        """(N, 3) for each of the unit `directions` (N, 3) on `surface` (N,) that `assign` moves,
        the direction `angle` (radians) past the proxy's edge on its new surface's side
        (`SurfaceEdge.across`); the others as they are."""
        out = np.array(directions, copy=True)
        for edge in self.edges:
            move = edge.moved(directions) & ((surface == edge.first) | (surface == edge.second))
            out[move] = edge.across(directions[move], angle * edge.scale)
        return out


def find_surface_edges(photo: np.ndarray, shows: np.ndarray, behind: np.ndarray, hidden: np.ndarray,
                       planes: dict[int, SurfacePlane], *, frame: Frame | None = None) -> SurfaceEdges:
    """The edges between the proxy's planar surfaces near the `hidden` pixels, each found where
    the photograph `photo` (h, w, 3 linear radiance) shows it. `shows` (h, w): the surface each
    pixel shows in the photograph (-1: the object, nothing, or what is not compared);
    `behind` (h, w): the surface each pixel sees without the object; `planes`: the surfaces that
    may meet, by id. The arrays hold the pixels of `frame` (default: the whole panorama)."""
    frame = frame or Frame.whole(hidden.shape)
    if not hidden.any():
        return SurfaceEdges(())
    pixel = np.pi / frame.height
    grow = dilate if frame.width > hidden.shape[1] else latlong.dilate
    near = grow(hidden, int(np.ceil(_SEARCH + _BAND)) + 1)
    pairs = _meeting_pairs(np.where(near, behind, -1), planes)
    if not pairs:
        return SurfaceEdges(())
    extent = max(int(np.ptp(np.nonzero(hidden)[0])), int(np.ptp(np.nonzero(hidden)[1])), int(2 * _SEARCH))
    region = grow(hidden, extent)
    rows, cols = np.nonzero(region)
    directions = latlong.pixel_directions_at(rows + frame.row0, np.mod(cols + frame.col0, frame.width),
                                             frame.width, frame.height)
    log_photo = np.log(np.maximum(photo[rows, cols], 1e-6))
    at = (shows[rows, cols], behind[rows, cols], hidden[rows, cols])
    edges = []
    for a, b in pairs:
        edge = _edge(planes, a, b, directions, log_photo, at, pixel)
        if edge is not None:
            edges.append(edge)
    return SurfaceEdges(tuple(edges))


def _meeting_pairs(labels: np.ndarray, planes: dict[int, SurfacePlane]) -> list[tuple[int, int]]:
    """The pairs of plane ids (a < b) of `planes` whose pixels in `labels` (h, w) touch, at least
    `_MIN_ADJACENT` times, one a floor or ceiling and the other not."""
    found = []
    for x, y in ((labels[:-1], labels[1:]), (labels[:, :-1], labels[:, 1:])):
        touch = (x != y) & (x >= 0) & (y >= 0)
        found.append(np.stack([np.minimum(x[touch], y[touch]), np.maximum(x[touch], y[touch])], axis=1))
    pairs, counts = np.unique(np.concatenate(found), axis=0, return_counts=True)
    return [(int(a), int(b)) for (a, b), n in zip(pairs, counts, strict=True)
            if n >= _MIN_ADJACENT and a in planes and b in planes
            and is_wall(planes[a].normal) != is_wall(planes[b].normal)]


def _edge(planes: dict[int, SurfacePlane], a: int, b: int, directions: np.ndarray, log_photo: np.ndarray,
          at: tuple[np.ndarray, np.ndarray, np.ndarray], pixel: float) -> SurfaceEdge | None:
    """The edge between surfaces `a` and `b` as the photograph shows it, from the region's
    pixels (their unit `directions`, log radiance, and (shows, behind, hidden) labels); None
    where the proxy's line passes by no hidden pixel of either surface."""
    shows, behind, hidden = at
    pa, pb = planes[a], planes[b]
    axis = np.cross(pa.normal, pb.normal)
    axis /= np.linalg.norm(axis)
    point = np.linalg.solve(np.stack([pa.normal, pb.normal, axis]), np.array([pa.offset, pb.offset, 0.0]))
    if np.linalg.norm(point) < 1e-9:
        return None  # the line passes through the probe: seen edge-on
    foot = point / np.linalg.norm(point)
    proxy = np.cross(foot, axis)
    x, y, z = directions @ proxy, directions @ foot, directions @ axis
    angle, along = np.arctan2(x, y), np.arctan2(z, np.hypot(x, y))
    facing = y > 0
    a_near = facing & (behind == a) & (np.abs(angle) < 4 * _SEARCH * pixel)
    if not a_near.any():
        return None
    if np.median(angle[a_near]) < 0:  # `a` on the positive side
        proxy, angle = -proxy, -angle
    in_hole = hidden & facing & ((behind == a) | (behind == b)) & (np.abs(angle) <= _SEARCH * pixel)
    if not in_hole.any():
        return None
    middle = float(np.median(along[in_hole]))
    # In pixels at the hole's middle: a turn about the axis moves the edge by turn cos(along).
    scale = float(np.cos(middle)) / pixel
    lo, hi = float(along[in_hole].min()), float(along[in_hole].max())
    # Measured beside the hole only (a room modelled by eye is off by different amounts along
    # a wall); the pixels change surface over the exemplar's reach around it.
    beside = max(_BESIDE * (hi - lo), 2 * _SEGMENT * pixel)
    reach = max(hi - lo, 2 * _SEARCH * pixel)
    offset = angle * scale
    seen = (~hidden & facing & ((shows == a) | (shows == b)) & (along >= lo - beside) & (along <= hi + beside))
    found = _strongest_step(offset[seen], _along(along[seen], middle, scale), along[seen] / pixel, log_photo[seen])
    shift, slope = found if found is not None else (0.0, 0.0)
    return SurfaceEdge(first=a, second=b, axis=axis, foot=foot, proxy=proxy, scale=scale, middle=middle,
                       shift=shift, slope=slope, span=(lo - reach, hi + reach), found=found is not None)


def _strongest_step(offset: np.ndarray, position: np.ndarray, along: np.ndarray, values: np.ndarray
                    ) -> tuple[float, float] | None:
    """The line offset = shift + slope position (pixels) across which the colours `values`
    (N, C) step most consistently: the step between the mean colours of a band on either side,
    per segment along the edge (`along`, pixels), averaged as vectors over the segments so that
    steps of one sign and colour all along add up and a desk's or a rug's edge in one segment
    does not. The proxy's own line (0, 0) where none steps `_OVER_PROXY` times more than it or
    the best lies within `_MIN_SHIFT` of it at the hole's middle; None where the proxy's line is
    not seen in enough segments, or where the edge found steps less than `_PROMINENCE` times the
    typical candidate or `_MIN_STEP`, or lies at the search range's end."""
    if not len(offset):
        return None
    bands = round(_BAND / _BIN)
    half = int(np.ceil((_SEARCH + _BAND) / _BIN))
    segment = np.floor((along - along.min()) / _SEGMENT).astype(np.int64)
    n_seg, n_bin, c = int(segment.max()) + 1, 2 * half, values.shape[1]
    extent = max(float(np.abs(position).max()), 1.0)
    slopes = np.linspace(-1.0, 1.0, 2 * int(_SEARCH) + 1) * min(_SEARCH / extent, _MAX_SLOPE)
    e = np.arange(bands, n_bin - bands + 1)  # a line between bins e - 1 and e
    lines = (e - half) * _BIN
    search = np.abs(lines) <= _SEARCH
    scores = np.zeros((len(slopes), len(e)))
    proxy_seen = False
    for i, slope in enumerate(slopes):
        moved = offset - slope * position
        keep = np.abs(moved) < _SEARCH + _BAND
        index = segment[keep] * n_bin + np.floor(moved[keep] / _BIN).astype(np.int64) + half
        count = np.bincount(index, minlength=n_seg * n_bin).reshape(n_seg, n_bin)
        total = np.stack([np.bincount(index, values[keep, j], minlength=n_seg * n_bin) for j in range(c)], axis=-1)
        cum_n = np.concatenate([np.zeros((n_seg, 1)), np.cumsum(count, axis=1)], axis=1)
        cum_v = np.concatenate([np.zeros((n_seg, 1, c)), np.cumsum(total.reshape(n_seg, n_bin, c), axis=1)], axis=1)
        n_lo, n_hi = cum_n[:, e] - cum_n[:, e - bands], cum_n[:, e + bands] - cum_n[:, e]
        v_lo, v_hi = cum_v[:, e] - cum_v[:, e - bands], cum_v[:, e + bands] - cum_v[:, e]
        both = (n_lo >= _MIN_BAND_PIXELS) & (n_hi >= _MIN_BAND_PIXELS)
        step = (v_hi / np.maximum(n_hi, 1)[..., None] - v_lo / np.maximum(n_lo, 1)[..., None]) * both[..., None]
        segments = both.sum(axis=0)
        mean = step.sum(axis=0) / np.maximum(segments, 1)[:, None]
        scores[i] = np.where((segments >= _MIN_SEGMENTS) & search, np.linalg.norm(mean, axis=-1), 0.0)
        if slope == 0.0:  # the proxy's own line
            proxy_seen = segments[np.argmin(np.abs(lines))] >= _MIN_SEGMENTS
    if not (scores > 0).any():
        return None
    i, j = np.unravel_index(int(np.argmax(scores)), scores.shape)
    proxy = scores[len(slopes) // 2, np.argmin(np.abs(lines))]
    edge = max(_PROMINENCE * float(np.median(scores[scores > 0])), _MIN_STEP)
    if not proxy_seen:
        return None
    if scores[i, j] < _OVER_PROXY * proxy or abs(lines[j]) < _MIN_SHIFT:
        return (0.0, 0.0) if proxy >= edge else None
    if scores[i, j] < edge or abs(lines[j]) >= _SEARCH:
        return None
    return float(lines[j]), float(slopes[i])
