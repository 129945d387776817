"""The working-resolution solution applied to the full-resolution panorama.

The change of light is smooth on a surface, so most full-resolution pixels take E and dE
bilinearly from their four working neighbours; a pixel whose neighbours see another surface
takes them from the neighbours on its own (found by testing the few triangles they see). A
pixel no neighbour can serve, one beside the object, and one on a sharp shadow edge (its
neighbours' relative change differs widely) gets its own light, computed like a working
pixel's. The hidden region is filled at the panorama's own resolution. The panorama is read
and the difference written in bands of rows, into one float32 image.
"""
from __future__ import annotations

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from ..callbacks import RunCallbacks
from ..geometry import latlong
from ..geometry.mesh import surfaces_of
from ..geometry.planeraster import PlaneRaster, build_raster
from ..light.radiosity import LUMA
from ..radiance import clamped_rows
from ..report import Report
from ..side_by_side import both, each
from ..synthesis.plane_fill import PanoramaMaps, PanoramaReflectance
from ..synthesis.surface_edges import SurfaceEdges
from .compose import ratio_change, reference_irradiance
from .fill import (
    FilledReflectance,
    HiddenLight,
    Revealed,
    filled_reflectance,
    hidden_light,
    hidden_planes,
    lifted,
    measured_reflectance,
    moved_across,
    onto_photographed,
    relit_ratio,
    surface_edges,
    surface_footprint,
)
from .local import PointLight, Receiving, light_at
from .object_window import ObjectWindow, object_window
from .refine_samples import refine_samples, sample_stride
from .relit_noise import QuietRelit, relit_noise_stage
from .seam import seamless_block_change
from .solution import Solution
from .working_maps import Cells, WorkingMaps, cells, nearest_working, neighbours, surfaces_seen, working_maps

# Full-resolution pixels per band. The upsample's passes are bound by memory: a band whose
# arrays (1.5 MB each) stay in a core's cache took 1.5 s at 8K against 2.3 s for bands of 4x
# the pixels, and two bands side by side then run nearly twice as fast as one.
_BAND_PIXELS = 1 << 17
_SHARP = 0.1  # neighbours whose dE / E differ by more than this leave the pixel to be refined


@dataclass(frozen=True)
class FullResolution:
    """The full-resolution difference (H, W, 3) float32, the hidden mask (H, W) and whether
    every hidden pixel was filled."""

    difference: np.ndarray
    hidden_mask: np.ndarray
    filled: bool


@dataclass(frozen=True)
class _Refine:
    """Full-resolution pixels that get their own light: flat index, what they see."""

    pixel: np.ndarray
    tri: np.ndarray
    bary: np.ndarray
    distance: np.ndarray
    spread: np.ndarray  # how much its neighbours' dE / E differ; inf where the pixel must be refined
    beside: np.ndarray  # bool: beside the object's silhouette (its light is computed at the pixel itself)

    def take(self, chosen: np.ndarray) -> _Refine:
        return _Refine(*(getattr(self, f)[chosen] for f in _Refine.__dataclass_fields__))


@dataclass(frozen=True)
class _Canvas:
    """The full-resolution panorama `hdri` (H, W, 3) and what the light stages write for it:
    the `difference` (H, W, 3) float32 and, over the object's `window`, the irradiance
    `window_e` with the object (None without a window); `e_ref` is what "E is ~0" is relative
    to."""

    hdri: np.ndarray
    difference: np.ndarray
    window: ObjectWindow | None
    window_e: np.ndarray | None
    e_ref: float


def full_resolution(solution: Solution, hdri: np.ndarray, rep: Report, callbacks: RunCallbacks) -> FullResolution:
    """Apply the working `solution` to the full-resolution panorama `hdri` (H, W, 3)."""
    height, width = hdri.shape[:2]
    full = (height, width)
    maps = working_maps(solution)
    with rep.stage("window"):
        window = object_window(solution.geo, solution.target, solution.traced.hidden_map,
                               _exemplar_extent(solution), full, maps, solution.seen)
    if window is not None:
        rep.info["object_window"] = list(window.hidden.shape[::-1])  # width, height
    apply = ~solution.traced.hidden_h & ~solution.room.pixels.emitter_h
    e_ref = reference_irradiance(solution.e_h, apply)
    difference = np.zeros((height, width, 3), dtype=np.float32)
    window_e = None if window is None else np.zeros((*window.hidden.shape, 3), dtype=np.float32)
    canvas = _Canvas(hdri=hdri, difference=difference, window=window, window_e=window_e, e_ref=e_ref)
    with rep.stage("upsample"):
        refine = _upsample(solution, maps, canvas, rep, callbacks)
    callbacks.check()
    with rep.stage("refine"):
        _refine(solution, refine, canvas, rep, callbacks)
    hidden_mask = np.zeros(full, dtype=bool)
    if window is None:
        rep.skip("relit_noise", "the object is not visible from the probe centre: no window to measure noise in")
        rep.skip("synthesis", "the object is not visible from the probe centre: no hidden region to fill")
        return FullResolution(difference, hidden_mask, True)
    rows, cols = _window_pixels(window)
    hidden_mask[rows, cols] = window.hidden
    surfaces = _window_surfaces(solution, window, window_e, e_ref)
    radiance = np.maximum(hdri[rows, cols], 0.0)
    revealed = window.hidden & (window.tri >= 0)

    found = None
    if revealed.any():
        with rep.stage("hidden_light"):
            found = _revealed(solution, window, window_e, radiance, surfaces, revealed,
                              relit=relit_ratio(radiance, difference[rows, cols]))

    def synthesis() -> FilledReflectance | None:
        """The revealed pixels' reflectance and the lift of the object's shadow beside them
        (`filled_reflectance`), None where there are none."""
        if found is None:
            return None
        with rep.stage("synthesis"):
            return filled_reflectance(solution, found, rep, callbacks)

    def light() -> tuple[QuietRelit, HiddenLight | None]:
        """The relit pixels' noise matched, and the revealed pixels' light after the removal."""
        quiet = relit_noise_stage(radiance, difference[rows, cols], np.where(surfaces.measured, surfaces.without, -1),
                                  enabled=solution.params.match_relit_noise, rep=rep)
        if found is None:
            return quiet, None
        with rep.stage("hidden_light"):
            return quiet, hidden_light(solution, found, callbacks)

    # The hidden pixels' texture is synthesised on a second thread while the relit pixels'
    # noise is matched and the light after the removal is found (the 8K box's 1.4 s of
    # synthesis beside 0.45 and 0.7 s): none of them reads what another writes, and the fill's
    # pixels are written over the matched noise after.
    (quiet, after), filled = both(light, synthesis)
    difference[rows, cols] = quiet.change
    if found is None:
        rep.skip("synthesis", "nothing is behind the object to fill")
    else:
        with rep.stage("synthesis"):
            difference[rows[revealed], cols[revealed]] = after.change(filled.rho, found.radiance)
            change = lifted(radiance, difference[rows, cols], filled.lift)
            surface = found.panorama.maps.surface_without.copy()  # the surfaces as the fill took them
            surface[revealed] = solution.target.surface_key[found.tri]
            continued, unrepeated = np.zeros_like(revealed), np.zeros_like(revealed)
            continued[revealed], unrepeated[revealed] = filled.continued, filled.unrepeated
            difference[rows, cols] = seamless_block_change(radiance, change, revealed, surface, continued=continued,
                                                           unrepeated=unrepeated)
    unseen = int(window.hidden.sum() - revealed.sum())
    if unseen:
        rep.warn(f"{unseen} pixels of the object see no proxy geometry behind it; they are left unchanged")
    return FullResolution(difference, hidden_mask, unseen == 0)


def _exemplar_extent(solution: Solution) -> np.ndarray:
    """(N, 3) points spanning the rasters the fill will read its exemplars from (the working
    solution's revealed points stand for the full-resolution ones)."""
    behind = solution.traced.behind
    if not len(behind.revealed):
        return np.zeros((0, 3))
    spans = []
    for _, plane in hidden_planes(solution.geo, solution.target.surface_key, behind.tri, behind.points):
        raster = build_raster(plane.normal, plane.points, cell=1e-9, margin=solution.params.exemplar_margin,
                              max_cells=1, along=plane.along)
        spans.append(_raster_outline(raster))
    return np.concatenate(spans)


def _raster_outline(raster: PlaneRaster, *, steps: int = 64) -> np.ndarray:
    """(N, 3) points on a raster's plane filling its rectangle (a grid, so the rectangle's
    image in the panorama is covered wherever it bends)."""
    h, w = raster.shape
    t = np.linspace(0.0, 1.0, steps)
    i, j = np.meshgrid(t * h * raster.cell, t * w * raster.cell, indexing="ij")
    return (raster.origin + i[..., None] * raster.v + j[..., None] * raster.u).reshape(-1, 3)


def _window_pixels(window: ObjectWindow) -> tuple[np.ndarray, np.ndarray]:
    """(h, w) panorama rows and columns of the window's pixels."""
    f = window.frame
    h, w = window.hidden.shape
    rows = np.broadcast_to((f.row0 + np.arange(h))[:, None], (h, w))
    cols = np.broadcast_to(np.mod(f.col0 + np.arange(w), f.width)[None, :], (h, w))
    return rows, cols


def _upsample(solution: Solution, maps: WorkingMaps, canvas: _Canvas, rep: Report, callbacks: RunCallbacks
              ) -> _Refine:
    """Write the upsampled change band by band; the pixels left to refine."""
    hdri, difference, window, window_e = canvas.hdri, canvas.difference, canvas.window, canvas.window_e
    height, width = hdri.shape[:2]
    grid = cells(maps)
    top, bottom = Cells.rows(maps)
    x = (np.arange(width) + 0.5) * (maps.width / width) - 0.5
    col = np.mod(np.floor(x).astype(np.int64), maps.width)
    col_next = np.mod(col + 1, maps.width)
    fx = (x - np.floor(x)).astype(np.float32)[None, :, None]
    gx = 1 - fx
    e_map = maps.e.reshape(maps.height, maps.width, 3)
    de_map = maps.de.reshape(maps.height, maps.width, 3)
    band = max(1, _BAND_PIXELS // width)

    def band_of(start: int) -> _Refine:
        """Write the band of rows from `start`; its pixels left to refine."""
        callbacks.check()
        rows = np.arange(start, min(start + band, height))
        y = (rows + 0.5) * (maps.height / height) - 0.5
        pair = np.clip(np.floor(y).astype(np.int64) + 1, 0, maps.height)
        fy = (y - np.floor(y)).astype(np.float32)[:, None, None]

        def bilinear(image: np.ndarray) -> np.ndarray:
            across = image[top[pair]] * (1 - fy) + image[bottom[pair]] * fy
            # In place on the band: np.take and *= instead of indexing and a sum of two
            # products, a third of the time at 8K (the same float32 operations).
            left, right = np.take(across, col, axis=1), np.take(across, col_next, axis=1)
            left *= gx
            right *= fx
            left += right
            return left

        e, de = bilinear(e_map).reshape(-1, 3), bilinear(de_map).reshape(-1, 3)
        plain = np.take(grid.plain[pair], col, axis=1).ravel()
        cell_spread = np.take(grid.spread[pair], col, axis=1).ravel()
        sharp = plain & (cell_spread > _SHARP)
        pixels = _BandPixels.of(rows, width, window, solution.target.surface_key)
        # The pixels the cells cannot serve as they are: those of a mixed cell, and in the
        # window those hidden, beside the object or on another surface than their cell's
        # (only the window's pixels are known yet: the rest of the band is left as it is).
        fast = plain.copy()
        inside = pixels.window_index
        if len(inside):
            cell_key = maps.key.reshape(maps.height, maps.width)[top[pair][inside // width], col[inside % width]]
            fast[inside] &= ~pixels.hidden[inside] & ~pixels.ring[inside] & (pixels.own[inside] == cell_key)
        slow = np.flatnonzero(~fast & ~pixels.hidden)
        served = fast.copy()
        refine = np.zeros(len(plain), dtype=bool)
        spread = np.where(sharp, cell_spread, 0.0)
        if len(slow):
            got = _mixed(solution, maps, pixels, rows, width, slow, height)
            e[slow], de[slow] = got.e, got.de
            served[slow] = got.served
            refine[slow] = got.needed
            spread[slow[got.needed]] = np.inf
        # Sharp edges are refined where the pixel's surface is known (looked up if need be).
        sharp &= fast
        pixels.look_up(solution, maps, rows, width, height, np.flatnonzero(sharp & ~pixels.known))
        at = np.flatnonzero(sharp)
        refine[at[pixels.tri[at] >= 0]] = True
        radiance = clamped_rows(hdri, rows[0], rows[-1] + 1).reshape(-1, 3)
        ratio_change(radiance, e, de, served, e_ref=canvas.e_ref, rep=rep,
                     out=difference[rows[0]:rows[-1] + 1].reshape(-1, 3))
        if window_e is not None and len(pixels.window_index):
            window_e[pixels.window_rows, pixels.window_cols] = e[pixels.window_index]
        idx = np.flatnonzero(refine)
        return _Refine(rows[0] * width + idx, pixels.tri[idx], pixels.bary[idx], pixels.distance[idx],
                       spread[idx], pixels.ring[idx])

    # Bands side by side, each writing rows of its own; the pixels to refine in the bands' order.
    parts = each(band_of, range(0, height, band))
    return _Refine(*(np.concatenate([getattr(p, f) for p in parts]) for f in _Refine.__dataclass_fields__))


@dataclass
class _BandPixels:
    """What a band's pixels (flat, band-local) are known to see: in the object's window from
    its trace; elsewhere looked up when needed (`known` marks where it is)."""

    known: np.ndarray
    hidden: np.ndarray
    ring: np.ndarray
    own: np.ndarray  # surface key seen (-1 for nothing)
    tri: np.ndarray
    bary: np.ndarray
    distance: np.ndarray
    window_index: np.ndarray  # band-local pixels inside the window ...
    window_rows: np.ndarray  # ... and where the window holds them
    window_cols: np.ndarray
    keys: np.ndarray  # the geometry's surface keys

    @classmethod
    def of(cls, rows: np.ndarray, width: int, window: ObjectWindow | None, keys: np.ndarray) -> _BandPixels:
        n = len(rows) * width
        pixels = cls(np.zeros(n, dtype=bool), np.zeros(n, dtype=bool), np.zeros(n, dtype=bool),
                     np.full(n, -1, dtype=np.int32), np.full(n, -1, dtype=np.int32), np.zeros((n, 2)), np.zeros(n),
                     np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), keys)
        if window is None:
            return pixels
        f = window.frame
        h, w = window.hidden.shape
        inside = np.flatnonzero((rows >= f.row0) & (rows < f.row0 + h))
        if not len(inside):
            return pixels
        cols = np.mod(f.col0 + np.arange(w), width)
        index = (inside[:, None] * width + cols[None, :]).ravel()
        wr = np.repeat(rows[inside] - f.row0, w)
        wc = np.tile(np.arange(w), len(inside))
        pixels.window_index, pixels.window_rows, pixels.window_cols = index, wr, wc
        pixels.known[index] = True
        pixels.hidden[index] = window.hidden[wr, wc] | window.kept[wr, wc]
        pixels.ring[index] = window.ring[wr, wc]
        pixels.tri[index] = window.tri[wr, wc]
        pixels.bary[index] = window.bary[wr, wc]
        pixels.distance[index] = np.where(pixels.tri[index] >= 0, window.distance[wr, wc], 0.0)
        pixels.own[index] = surfaces_of(keys, pixels.tri[index])
        pixels.own[pixels.hidden] = -1
        return pixels

    def look_up(self, solution: Solution, maps: WorkingMaps, rows: np.ndarray, width: int, height: int,
                index: np.ndarray) -> None:
        """Find what the band's pixels `index` see, among their working neighbours' triangles."""
        if not len(index):
            return
        r, c = rows[0] + index // width, index % width
        found = surfaces_seen(latlong.pixel_directions_at(r, c, width, height),
                              nearest_working(r, c, (height, width), maps), solution.geo, maps)
        self.tri[index], self.bary[index], self.distance[index] = found.tri, found.bary, found.distance
        self.own[index] = surfaces_of(self.keys, found.tri)
        self.known[index] = True


@dataclass(frozen=True)
class _Mixed:
    """Light of the pixels of mixed cells from the neighbours on their own surface."""

    e: np.ndarray
    de: np.ndarray
    served: np.ndarray  # some neighbour on its surface served it
    needed: np.ndarray  # none did: the pixel is refined


def _mixed(solution: Solution, maps: WorkingMaps, pixels: _BandPixels, rows: np.ndarray, width: int,
           index: np.ndarray, height: int) -> _Mixed:
    """E and dE of band pixels `index` from the working neighbours that see their surface."""
    pixels.look_up(solution, maps, rows, width, height, index[~pixels.known[index]])
    r, c = rows[0] + index // width, index % width
    near = neighbours(r, c, (height, width), maps)
    own = pixels.own[index]
    same = (maps.key[near.index] == own[None, :]) & (own >= 0)[None, :]
    weight = near.weight * maps.valid[near.index] * same
    total = weight.sum(axis=0)
    weight = weight / np.where(total > 0, total, 1.0)[None, :]
    e = np.einsum("kn,knc->nc", weight, maps.e[near.index])
    de = np.einsum("kn,knc->nc", weight, maps.de[near.index])
    ring = pixels.ring[index]
    served = (total > 0) & ~ring
    # A pixel whose surface only lights neighbours that are light sources is one itself.
    emitter = (same & maps.emitter[near.index]).any(axis=0)
    needed = ~served & ~emitter & (pixels.tri[index] >= 0) | ring & (pixels.tri[index] >= 0)
    return _Mixed(e, de, served, needed)


def _refine(solution: Solution, refine: _Refine, canvas: _Canvas, rep: Report, callbacks: RunCallbacks) -> None:
    """Give the pixels to refine their own light (the sharp-edge ones up to the preset's budget)."""
    needed = np.isinf(refine.spread)
    optional = np.flatnonzero(~needed)
    budget = solution.params.refine_pixels
    keep = needed.copy()
    keep[optional[np.argsort(-refine.spread[optional], kind="stable")[:budget]]] = True
    rep.info["refined_pixels"] = {"needed": int(needed.sum()), "sharp_edges": int(min(len(optional), budget)),
                                  "sharp_edges_left": int(max(0, len(optional) - budget))}
    for beside in (True, False):
        chosen = refine.take(keep & (refine.beside == beside))
        if len(chosen.pixel):
            _refined_light(solution, chosen, canvas, rep, callbacks, per_point=beside)


def _refined_light(solution: Solution, refine: _Refine, canvas: _Canvas, rep: Report, callbacks: RunCallbacks, *,
                   per_point: bool) -> None:
    """Write the change of the pixels `refine` from their own light; on a panorama four or more
    times finer than the working copy from samples at half the working pixel's pitch."""
    height, width = canvas.hdri.shape[:2]
    stride = sample_stride(width // solution.traced.width)
    if stride == 1:
        light = _own_light(solution, refine, canvas, rep, callbacks, per_point=per_point)
        _write_light(solution, refine, light.e, light.de, canvas, rep)
        return
    known = _Known(refine, canvas.window, solution.target.surface_key, width)
    samples = refine_samples(refine.pixel, width, height, known.surface_at, stride=stride)
    light = _own_light(solution, known.take(samples.computed), canvas, rep, callbacks, per_point=per_point)
    counts = rep.info.setdefault("sampled_pixels", {"pixels": 0, "computed": 0})
    counts["pixels"] += len(refine.pixel)
    counts["computed"] += len(samples.computed)
    e = np.einsum("nk,nkc->nc", samples.weight, light.e[samples.corner])
    de = np.einsum("nk,nkc->nc", samples.weight, light.de[samples.corner])
    _write_light(solution, refine, e, de, canvas, rep)


@dataclass(frozen=True)
class _Known:
    """What the pixels refined and those of the object's window see: the samples of the
    refined pixels' light are taken among both (the window lets the pixels beside the object
    take samples beyond their ring)."""

    refine: _Refine
    window: ObjectWindow | None
    keys: np.ndarray  # the geometry's surface keys
    width: int

    @cached_property
    def _order(self) -> np.ndarray:
        """The rows of `refine` in the order of their pixels."""
        return np.argsort(self.refine.pixel)

    def _among(self, flat: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Rows of `refine` holding the flat pixels, and whether it holds them."""
        order = self._order
        at = np.minimum(np.searchsorted(self.refine.pixel[order], flat), len(order) - 1)
        return order[at], self.refine.pixel[order[at]] == flat

    def _in_window(self, flat: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Window rows and columns of the flat pixels, and where it shows a surface for them."""
        if self.window is None:
            return np.zeros(len(flat), dtype=np.int64), np.zeros(len(flat), dtype=np.int64), np.zeros(len(flat), bool)
        w = self.window
        wr, wc, inside = w.holds(*np.divmod(flat, self.width))
        return wr, wc, inside & ~w.hidden[wr, wc] & ~w.kept[wr, wc] & (w.tri[wr, wc] >= 0)

    def surface_at(self, rows: np.ndarray, cols: np.ndarray) -> np.ndarray:
        flat = rows * self.width + cols
        index, found = self._among(flat)
        wr, wc, seen = self._in_window(flat)
        tri = np.where(found, self.refine.tri[index], -1)
        if self.window is not None:
            tri = np.where(seen, self.window.tri[wr, wc], tri)
        return surfaces_of(self.keys, tri)

    def take(self, flat: np.ndarray) -> _Refine:
        """The pixels `flat` (each refined or seen in the window) as pixels to compute."""
        index, _ = self._among(flat)
        chosen = self.refine.take(index)
        wr, wc, seen = self._in_window(flat)
        if not seen.any():
            return chosen
        w = self.window
        return replace(chosen, pixel=flat, tri=np.where(seen, w.tri[wr, wc], chosen.tri),
                       bary=np.where(seen[:, None], w.bary[wr, wc], chosen.bary),
                       distance=np.where(seen, w.distance[wr, wc], chosen.distance))


def _own_light(solution: Solution, refine: _Refine, canvas: _Canvas, rep: Report, callbacks: RunCallbacks, *,
               per_point: bool) -> PointLight:
    """The light of full-resolution pixels (`refine`: flat pixel, the triangle it sees at its
    barycentric weights and distance) from their own transport."""
    tri, bary = refine.tri, refine.bary
    height, width = canvas.hdri.shape[:2]
    rows, cols = np.divmod(refine.pixel, width)
    room, geo, target = solution.room, solution.geo, solution.target
    points = latlong.pixel_directions_at(rows, cols, width, height) * refine.distance[:, None]
    patch, corners, weights = room.patches.lattice.locate(tri, bary)
    relit = ~room.emitter[patch]
    if target.planes:
        relit &= np.isin(geo.tri_object[tri], target.planes)
    receiving = Receiving(points=points, normals=geo.normals[tri], tri=tri, bary=bary,
                          corners=room.receivers.vertex_row[corners], weights=weights, relit=relit)
    light = light_at(solution.lit, receiving, solution.params, callbacks, per_point=per_point)
    key = "refined_exact_pairs"
    rep.info[key] = rep.info.get(key, 0) + light.exact_pairs
    return light


def _write_light(solution: Solution, refine: _Refine, e: np.ndarray, de: np.ndarray, canvas: _Canvas,
                 rep: Report) -> None:
    """Write the change of the pixels `refine` from their light E and dE (N, 3)."""
    pixel, hdri, room = refine.pixel, canvas.hdri, solution.room
    patch, _, _ = room.patches.lattice.locate(refine.tri, refine.bary)
    radiance = np.maximum(hdri.reshape(-1, 3)[pixel].astype(np.float64), 0.0)
    canvas.difference.reshape(-1, 3)[pixel] = ratio_change(radiance, e, de, ~room.emitter[patch],
                                                           e_ref=canvas.e_ref, rep=rep)
    if canvas.window is not None and canvas.window_e is not None:
        wr, wc, inside = canvas.window.holds(*np.divmod(pixel, hdri.shape[1]))
        canvas.window_e[wr[inside], wc[inside]] = e[inside]


@dataclass(frozen=True)
class _WindowSurfaces:
    """Per window pixel: the surface key it sees without the object (-1 for none) and whether
    it measures a reflectance (not hidden, not a light, not too dark)."""

    without: np.ndarray
    measured: np.ndarray


def _window_surfaces(solution: Solution, window: ObjectWindow, window_e: np.ndarray, e_ref: float
                     ) -> _WindowSurfaces:
    """What the window's pixels see, for the noise match and the exemplar."""
    keys = solution.target.surface_key.astype(np.int32)
    room_hit = np.isfinite(window.distance) & ~window.on_object
    emitter = np.zeros(window.hidden.shape, dtype=bool)
    # Only the pixels on a triangle with a light's patch are located: millions at 8K otherwise.
    patches = solution.room.patches
    lit = np.zeros(len(patches.levels), dtype=bool)
    lit[patches.patch_tri[solution.room.emitter]] = True
    on_light = room_hit & lit[window.tri]
    patch, _, _ = patches.lattice.locate(window.tri[on_light], window.bary[on_light].astype(np.float64))
    emitter[on_light] = solution.room.emitter[patch]
    measured = ~window.hidden & room_hit & ~emitter & ((window_e @ LUMA.astype(np.float32)) > 1e-3 * e_ref)
    return _WindowSurfaces(without=surfaces_of(keys, window.tri), measured=measured)


def _revealed(solution: Solution, window: ObjectWindow, window_e: np.ndarray, radiance: np.ndarray,
              surfaces: _WindowSurfaces, revealed: np.ndarray, *, relit: np.ndarray) -> Revealed:
    """The window's revealed pixels and its reflectance measured from its `radiance` (h, w, 3)
    (`relit`, h, w: the relighting's change of light there, E' / E), at full resolution (float32:
    the maps span millions of pixels). As on the working panorama (`fill.working_revealed`), the
    pixels between a proxy's surface edge and the photograph's are on the surface the photograph
    shows there, revealed and seen alike."""
    frame = window.frame
    rows, cols = _window_pixels(window)
    keys = solution.target.surface_key.astype(np.int32)
    surface_with = surfaces_of(keys, np.where(window.on_object, window.object_tri, window.tri))
    # found at the panorama's resolution: a few of its pixels off are a fraction of a working one
    edges = surface_edges(solution, radiance, surface_with, surfaces.without, window.hidden, frame)
    distance_with = np.where(window.on_object, window.object_distance, window.distance)
    finite = np.isfinite(window.distance)
    maps = PanoramaMaps(surface_with, np.where(np.isfinite(distance_with), distance_with, 0.0),
                        surfaces.without.copy(), np.where(finite, window.distance, 0.0), window.hidden, frame=frame)
    del distance_with
    measured = surfaces.measured
    rho = measured_reflectance(radiance.reshape(-1, 3), window_e.reshape(-1, 3), measured.ravel())
    rho = rho.reshape(radiance.shape).astype(np.float32, copy=False)
    _move_across(solution, edges, maps, rho, radiance, measured, rows, cols)
    directions = latlong.pixel_directions_at(rows[revealed], cols[revealed], frame.width, frame.height)
    tri, bary, points = onto_photographed(edges, solution, directions, window.tri[revealed].astype(np.int64),
                                          window.bary[revealed].astype(np.float64),
                                          directions * window.distance[revealed].astype(np.float64)[:, None])
    solid = latlong.pixel_solid_angles(frame.width, frame.height)[rows[revealed], 0]
    footprint = surface_footprint(solid, directions, solution.geo.normals[tri], np.linalg.norm(points, axis=1))
    return Revealed(tri=tri, bary=bary, points=points, radiance=radiance[revealed].astype(np.float64),
                    footprint=footprint, panorama=PanoramaReflectance(rho, measured, maps, relit), edges=edges)


def _move_across(solution: Solution, edges: SurfaceEdges, maps: PanoramaMaps, rho: np.ndarray, radiance: np.ndarray,
                 measured: np.ndarray, rows: np.ndarray, cols: np.ndarray) -> None:
    """The window's `measured` pixels (h, w) the photograph shows across a surface edge from the
    proxy (`fill.moved_across`) put on that surface in `maps` and `rho` (h, w, 3), in place; so many
    pixels at a time as a band holds (the window's directions would take tens of MB at once)."""
    frame = maps.frame
    pixel = np.flatnonzero(measured)
    keys = maps.surface_with.ravel()
    for start in range(0, len(pixel), _BAND_PIXELS):
        flat = pixel[start:start + _BAND_PIXELS]
        r, c = np.unravel_index(flat, measured.shape)
        directions = latlong.pixel_directions_at(rows[r, c], cols[r, c], frame.width, frame.height)
        across = moved_across(edges, solution, directions, keys[flat], radiance[r, c])
        r, c = r[across.index], c[across.index]
        maps.surface_with[r, c] = maps.surface_without[r, c] = across.surface
        maps.distance_with[r, c] = maps.distance_without[r, c] = across.distance
        rho[r, c] = across.rho
