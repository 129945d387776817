"""What the removed object hid from the probe: reflectance synthesised on the plane, lit anew.

Reflectance, not radiance, is synthesised: rho = pi L / E carries no shadow, so the
shadow gradients around the object cannot leak into the fill, and the filled floor is then lit
by the irradiance after the removal, L' = rho E' / pi. Synthesis runs on a rectified raster of
the revealed plane (`geometry.planeraster`), the exemplar being the same surface's visible cells around
the hole.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..errors import DimredError
from ..geometry import latlong, planeraster
from ..light.radiosity import LUMA
from ..segmentation.masks import box_mean
from .crossing import fill_crossing, find_crossing
from .lines import sharpened_across
from .material import Material, border_material, sharp_exemplar, wall_material
from .plank_profile import PlankProfile, fold_profile
from .shadow_lift import ShadowLift, lift_gain, shadow_lift
from .structure import Filled, fill_structured
from .texture import SynthesisParams
from .wall_columns import fill_wall

_MAX_CELLS = 512 * 512  # bounds the raster (and the exemplar) whatever the panorama size
_DEPTH_TOLERANCE = 0.02  # relative: a cell is where a ray meets its surface within this
_MIN_KNOWN = 64  # visible cells a surface needs to serve as its own exemplar
# Planks whose profile across them is not found (`plank_profile`): the detail across the lines
# interpolated along them, amplified before they are looked up (`lines.sharpened_across`). At an
# interpolated line's middle the two ends' grain streaks average to half their spread, and the
# lookups from the panorama into the raster and back blur what is left (each about a
# [1/4, 1/2, 1/4] kernel across the lines). Unlike the copies' grain (`structure._PLANK_DETAIL`,
# weighed 0.9 with it), this detail lies where the truth's does. Against gain 0 with the copies'
# grain weighed 1.45, at 1024x512 the structure rose by 0.02-0.12 on five plank floors at 64
# samples and by 0.02-0.08 on six at 16, the detail ratio staying within 0.80-1.12. Gain 3 gave
# no more structure (within 0.01) for a detail ratio up to 1.31.
_LINE_SHARPENING = 2.0
# Planks whose profile is found: the profile gives the lines their seams, neither sharpened nor
# much grain over them. At 1024x512 on six plank floors at 16 samples (the demo at 32), the
# copies' grain weighed 0, 0.3 and 0.45 gave structure 0.70-0.74, 0.69-0.74 and 0.69-0.73 for
# detail ratios 0.78-0.85, 0.81-0.91 and 0.84-0.96; sharpened too (gain 1, weight 0) 0.67-0.73.
_PROFILED_DETAIL = 0.45
_PROFILE_PIXELS = 400_000  # seen pixels gathered for the planks' profile at most
# cells: the mean a pixel's own detail is taken against (1 or 3: within 0.02 in structure)
_PROFILE_MEAN_RADIUS = 2
# The photograph's detail a shift map's copy adds is the surface's grain. But a shift copies a
# whole stretch of floor, whatever lies in it, where the per-pixel synthesis picks each source
# by how its neighbourhood fits: a thin thing lying across a shifted copy's source (a desk
# chair's legs printed on the floor beside the hole, thinner than a raster cell and so not told
# from the material by the exemplar's colours) is no grain. It stands out of the copies' detail,
# and is clipped to `_GRAIN_SPREAD` times their robust spread (in luminance relative to the
# raster). On photo-textured hotel_box at 512x256 (seed 0) the chair's legs were drawn across the
# fill as a dark violet line: the detail ratio 1.68 -> 1.47, bruises 0.007 -> 0.002 of the fill.
# Bounding the synthesis's copies too cost the plank floors without structure their seams
# (walnut_crate's detail ratio 0.90 -> 0.81 at 1024x512) and hotel_walls' door edges.
_GRAIN_SPREAD = 6.0


@dataclass(frozen=True)
class PanoramaMaps:
    """(h, w) per pixel of `frame` (default: the whole panorama): the surface id and distance
    of the first hit with the object and without it (-1 where nothing is hit), and whether the
    object is the first hit."""

    surface_with: np.ndarray
    distance_with: np.ndarray
    surface_without: np.ndarray
    distance_without: np.ndarray
    hidden: np.ndarray
    frame: planeraster.Frame | None = None


@dataclass(frozen=True)
class PanoramaReflectance:
    """What the panorama tells about reflectance: (h, w, 3) rho = pi L / E, (h, w) where it
    was measured, the surfaces each pixel sees, and how the removal changes its light, over the
    pixels of the maps' frame."""

    rho: np.ndarray
    valid: np.ndarray
    maps: PanoramaMaps
    # (h, w) the relighting's change of light at each pixel (E' / E); None: not known (taken as
    # relit everywhere)
    relit: np.ndarray | None = None

    def shows(self, surface: int) -> np.ndarray:
        """(h, w) where the reflectance is measured on `surface` (seen first there: not where
        the object, or anything else, hides it)."""
        return self.valid & (self.maps.surface_with == surface)


@dataclass(frozen=True)
class HiddenPlane:
    """The hidden points (N, 3) of one plane: its surface id, unit normal, and the direction
    the raster's axes follow on a floor or ceiling (`planeraster.plane_axes`), or None."""

    surface: int
    normal: np.ndarray
    points: np.ndarray
    along: np.ndarray | None = None


@dataclass(frozen=True)
class FillOptions:
    """The raster's cell size (about the panorama's pixel footprint there), the exemplar margin
    (times the hole's extent around it), the synthesis's parameters and its seed."""

    cell: float
    margin: float
    synthesis: SynthesisParams
    seed: int = 0
    # compose tiled and planked floors from shifted copies first (`structure`), and continue a band
    # that crosses the hole (`crossing`)
    structure: bool = True


@dataclass(frozen=True)
class SurfaceFill:
    rho: np.ndarray  # (N, 3) reflectance at the hidden points
    raster_shape: tuple[int, int]
    cell: float
    known_cells: int
    hole_cells: int
    synthesised: bool  # False: too little of the surface is seen; its mean reflectance is used
    material: Material  # which seen cells served as exemplar
    structured: int = 0  # hole cells composed from shifted copies (the rest: order-independent synthesis)
    band_cells: int = 0  # hole cells of a band continued across the hole (`crossing`)
    # (h, w, 3) over the panorama maps' pixels, the factor per channel that lifts the object's
    # shadow the relighting left darker than this surface beside the hole (`shadow_lift`); None:
    # no such shadow
    lift: np.ndarray | None = None

    @property
    def lifted_pixels(self) -> int:
        return 0 if self.lift is None else int((self.lift > 1).any(axis=-1).sum())

    @property
    def continued(self) -> bool:
        """The fill continues the photograph's structure from copies: mostly a tiling's or
        planks' shifted copies, or a wall's columns."""
        return self.material.source == "wall columns" or (
            self.hole_cells > 0 and self.structured >= 0.5 * self.hole_cells)


def fill_surface(
    panorama: PanoramaReflectance,
    plane: HiddenPlane,
    options: FillOptions,
    *,
    cancel: Callable[[], bool] | None = None,
    progress: Callable[[np.ndarray], None] | None = None,
) -> SurfaceFill:
    """Reflectance at the plane's hidden points, synthesised on a raster covering them and the
    options' margin around, from the panorama's reflectance where it is valid and shows this
    surface. `progress(rho)` gets the (N, 3) reflectance at the points after each synthesis
    level, coarsest first."""
    maps, points = panorama.maps, plane.points
    raster = planeraster.build_raster(plane.normal, points, cell=options.cell, margin=options.margin,
                                      max_cells=_MAX_CELLS, along=plane.along)
    flags = planeraster.classify(raster, maps.surface_with, maps.distance_with, maps.surface_without,
                                 maps.distance_without, maps.hidden, surface=plane.surface,
                                 tolerance=_DEPTH_TOLERANCE, frame=maps.frame)
    values, weight = planeraster.sample_panorama(raster, panorama.rho, panorama.shows(plane.surface),
                                                 frame=maps.frame)
    known = (flags == planeraster.SEEN) & (weight > 0.5)
    # The hidden points are looked up bilinearly: fill the cells around each as well.
    r, c = (np.floor(x).astype(np.int64) for x in raster.coords(points))
    hole = np.zeros(raster.shape, dtype=bool)
    h, w = raster.shape
    for dr in (0, 1):
        for dc in (0, 1):
            hole[np.clip(r + dr, 0, h - 1), np.clip(c + dc, 0, w - 1)] = True
    hole |= flags == planeraster.HIDDEN
    hole &= ~known
    # A wall's hole is continued column by column from the wall itself (`wall_columns`): what the
    # photograph shows on it beside the hole (a door, a dark panel) is no clutter to leave out.
    wall = planeraster.is_wall(plane.normal)
    relit = None if wall or panorama.relit is None else planeraster.sample_panorama(
        raster, panorama.relit[..., None], panorama.shows(plane.surface), frame=maps.frame)[0][..., 0]
    material = wall_material(known) if wall else border_material(values, known, hole, min_cells=_MIN_KNOWN,
                                                                 relit=relit)
    crossing = find_crossing(values, known, hole) if options.structure and not wall else None
    if crossing is not None:  # each colour is copied only into its own region: nothing to repaint
        material = replace(material, replaced=np.zeros_like(material.replaced))
    # Only the hole's own material is copied; other things seen beside the hole (the object's
    # legs, a rug's edge) are repainted as context so that nothing continues them into it.
    exemplar, to_fill = material.exemplar, hole | material.replaced
    lift = None
    if not wall and crossing is None:  # a wall's columns and a band's regions are continued as they are
        shadow = shadow_lift(values, known, material, hole, relit=relit)
        if shadow is not None:
            # the fill meets, and copies from, the surface as the lifted photograph shows it
            lift = _lift(panorama, plane, raster, shadow)
            values = values * shadow.raster_gain(values, known)
            if lift is not None:
                panorama = replace(panorama, rho=panorama.rho * lift)
    mean = values[exemplar].mean(axis=0) if exemplar.any() else np.zeros(3)
    image = np.where(exemplar[..., None], values, mean)
    filled = None
    if exemplar.sum() >= _MIN_KNOWN:
        on_level = None if progress is None else (
            lambda _level, preview: progress(planeraster.sample_raster(raster, preview, points)))
        try:
            if crossing is not None:
                filled = fill_crossing(crossing, values, known, options.synthesis, seed=options.seed, cancel=cancel)
            elif wall:
                filled = fill_wall(image, exemplar, to_fill, options.synthesis, seed=options.seed, progress=on_level,
                                   cancel=cancel)
            else:
                # the repainted cells are composed anew, but what they show still weighs the copies there;
                # the shifted copies are read from the photograph itself, only the per-pixel synthesis
                # copies raster cells, which must be resolved about as finely as the hole's
                footprint = _footprint(raster)
                filled = fill_structured(image, exemplar, to_fill, options.synthesis, structure=options.structure,
                                         footprint=footprint if options.structure else None, guide=values,
                                         guided=material.replaced, seed=options.seed, progress=on_level,
                                         cancel=cancel, sources=sharp_exemplar(exemplar, footprint, to_fill))
        except DimredError:
            pass  # too little exemplar: the mean below is the honest fallback, reported by the caller
    if filled is None:
        rho = planeraster.sample_raster(raster, image, points)
    else:
        rho = _filled_rho(filled, panorama, plane, raster, image, exemplar)
    structure = None if filled is None else filled.structure
    return SurfaceFill(rho=rho, raster_shape=raster.shape, cell=raster.cell, known_cells=int(known.sum()),
                       hole_cells=int(to_fill.sum()), synthesised=filled is not None,
                       structured=0 if structure is None else int(structure.covered.sum()), material=material,
                       band_cells=crossing.band_cells if crossing is not None and filled is not None else 0,
                       lift=lift)


def _seen_points(panorama: PanoramaReflectance, rows: np.ndarray, cols: np.ndarray, raster: planeraster.PlaneRaster
                 ) -> tuple[np.ndarray, np.ndarray]:
    """(N, 3) the points the panorama maps' pixels (rows, cols) see (with the object), and (N,)
    which of them lie within `raster`."""
    maps = panorama.maps
    frame = maps.frame or planeraster.Frame.whole(maps.surface_with.shape)
    directions = latlong.pixel_directions_at(rows + frame.row0, np.mod(cols + frame.col0, frame.width), frame.width,
                                             frame.height)
    points = directions * maps.distance_with[rows, cols][:, None]
    row, col = raster.coords(points)
    h, w = raster.shape
    return points, (row >= 0) & (row <= h - 1) & (col >= 0) & (col <= w - 1)


def _lift(panorama: PanoramaReflectance, plane: HiddenPlane, raster: planeraster.PlaneRaster, shadow: ShadowLift
          ) -> np.ndarray | None:
    """(h, w, 3) over the panorama maps' pixels, the factor that lifts the `shadow` at each
    pixel that shows the plane's surface, by the pixel's own deficit (`shadow_lift.lift_gain`), 1
    elsewhere; None where it lifts none of them."""
    shows = panorama.shows(plane.surface)
    rows, cols = np.nonzero(shows)
    points, inside = _seen_points(panorama, rows, cols, raster)
    rows, cols, points = rows[inside], cols[inside], points[inside]
    weight = planeraster.sample_raster(raster, shadow.weight[..., None], points)[:, 0]
    on = weight > 0
    if not on.any():
        return None
    rows, cols, points = rows[on], cols[on], points[on]
    bound = None if shadow.bound is None else planeraster.sample_raster(raster, shadow.bound[..., None], points)[:, 0]
    lift = np.ones((*shows.shape, 3), np.float32)
    level = planeraster.sample_raster(raster, shadow.level, points)
    lift[rows, cols] = lift_gain(panorama.rho, shows, rows, cols, level=level, weight=weight[on], bound=bound)
    return lift if (lift > 1).any() else None


def _sharpened_lines(filled: Filled) -> np.ndarray:
    """The filled raster, its lines along planks (if any) sharpened across them for the lookup."""
    structure = filled.structure
    if structure is None or structure.lines is None:
        return filled.image
    return sharpened_across(filled.image, structure.lines, axis=structure.along, gain=_LINE_SHARPENING)


def _filled_rho(filled: Filled, panorama: PanoramaReflectance, plane: HiddenPlane, raster: planeraster.PlaneRaster,
                image: np.ndarray, known: np.ndarray) -> np.ndarray:
    """(N, 3) the filled raster at the plane's hidden points, with the photograph's detail finer
    than the raster (`_with_photograph_detail`). On planks, the lines interpolated along them
    take the planks' profile across them (`plank_profile`) where one is found; where none is,
    they are sharpened across instead and the copies' grain weighs more."""
    structure = filled.structure
    profile, across = None, None
    if structure is not None and structure.lines is not None:
        across = _along(raster, 1 - structure.along)
        profile = _plank_profile(panorama, plane, raster, image, known, structure.along)
    if profile is None:
        rho = planeraster.sample_raster(raster, _sharpened_lines(filled), plane.points)
        weight = 1.0 if structure is None else structure.detail
        return _with_photograph_detail(rho, panorama, plane, raster, _copy_field(filled, weight))
    rho = planeraster.sample_raster(raster, filled.image, plane.points)
    rho = _with_photograph_detail(rho, panorama, plane, raster, _copy_field(filled, _PROFILED_DETAIL))
    on_lines = structure.lines[_nearest_cells(raster, plane.points)]
    hidden = plane.points[on_lines]
    rho[on_lines] *= profile.at(hidden @ across, hidden @ _along(raster, structure.along))[:, None]
    return rho


def _nearest_cells(raster: planeraster.PlaneRaster, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(row, column) of the raster's cell nearest each point (clamped to the raster)."""
    return tuple(np.clip(np.rint(x).astype(np.int64), 0, n - 1)
                 for x, n in zip(raster.coords(points), raster.shape, strict=True))


def _plank_profile(panorama: PanoramaReflectance, plane: HiddenPlane, raster: planeraster.PlaneRaster,
                   image: np.ndarray, known: np.ndarray, along: int) -> PlankProfile | None:
    """The profile across the planks (which run along raster axis `along`) of the plane's pixels
    seen on the raster: each pixel's reflectance over the raster's mean around it (its own fine
    detail, free of the light and of the planks' shades), folded over the planks' width."""
    rows, cols = np.nonzero(panorama.shows(plane.surface))
    if len(rows) > _PROFILE_PIXELS:
        pick = np.sort(np.random.default_rng(0).choice(len(rows), _PROFILE_PIXELS, replace=False))
        rows, cols = rows[pick], cols[pick]
    points, inside = _seen_points(panorama, rows, cols, raster)
    mean, _ = box_mean((image @ LUMA)[..., None], known, _PROFILE_MEAN_RADIUS)
    local = planeraster.sample_raster(raster, mean, points[inside])[:, 0]
    value = panorama.rho[rows[inside], cols[inside]] @ LUMA
    ok = local > 1e-6 * max(float(local.max(initial=0.0)), 1e-30)
    seen_points = points[inside][ok]
    return fold_profile(seen_points @ _along(raster, 1 - along), seen_points @ _along(raster, along),
                        value[ok] / local[ok], min_width=4 * raster.cell)


def _along(raster: planeraster.PlaneRaster, axis: int) -> np.ndarray:
    """The unit direction on the plane along raster axis `axis` (0: rows, 1: columns)."""
    return raster.u if axis == 1 else raster.v


def _footprint(raster: planeraster.PlaneRaster) -> np.ndarray:
    """(h, w) how coarsely the lat-long panorama resolves each cell, up to a constant: the edge
    of a pixel (solid angle ~ cos latitude) projected at the cell's distance onto the plane."""
    pts = raster.points()
    dist = np.maximum(np.linalg.norm(pts, axis=-1), 1e-9)
    cos_lat = np.hypot(pts[..., 0], pts[..., 1]) / dist
    cos_incidence = np.abs(pts @ np.cross(raster.u, raster.v)) / dist
    return dist * np.sqrt(np.maximum(cos_lat, 1e-3) / np.maximum(cos_incidence, 1e-3))


@dataclass(frozen=True)
class _CopyField:
    """Per raster cell filled by a copy: `shift` (H, W, 2) from the cell to its source, in cells;
    `copied` (H, W) where there is one; `detail` (H, W) the weight of the photograph's finer
    detail there; `coarse` (H, W, C) the filled raster, which the photograph's detail is
    measured against at the copies' sources; `composed` (H, W) the cells of the shift map's
    copies."""

    shift: np.ndarray
    copied: np.ndarray
    detail: np.ndarray
    coarse: np.ndarray
    composed: np.ndarray


def _copy_field(filled: Filled, composed_detail: float) -> _CopyField:
    """Where the fill copied each cell from: the shift map's shifts where composed (their
    detail weighed `composed_detail`), the synthesis's sources elsewhere. The detail is measured
    against the filled raster, not the raster before the fill: a source beside the hole is
    looked up bilinearly with the hole's cells, which held the exemplar's mean before the fill.
    Against it, a dark door's cells at the hole's border read as far darker than their
    surroundings and left a dotted dark line along the border of a wall's fill (hotel_walls,
    the hotel photograph's curtain)."""
    sources, structure = filled.sources, filled.structure
    copied = sources[..., 0] >= 0
    shift = np.where(copied[..., None], sources - np.indices(copied.shape).transpose(1, 2, 0), 0)
    detail = np.ones(copied.shape)
    covered = np.zeros(copied.shape, dtype=bool) if structure is None else structure.covered
    if structure is not None:
        shift[covered] = structure.shifts.shifts[structure.shifts.labels[covered]]
        detail[covered] = composed_detail
        copied = copied | covered
    return _CopyField(shift, copied, detail, filled.image, covered)


def _with_photograph_detail(rho: np.ndarray, panorama: PanoramaReflectance, plane: HiddenPlane,
                            raster: planeraster.PlaneRaster, field: _CopyField) -> np.ndarray:
    """`rho` at the hidden points whose cell the fill copied from elsewhere (composed or
    synthesised), plus the detail of the photograph finer than the raster: the copy read from
    the panorama itself, at the point moved by the cell's shift, minus the same copy at the
    raster's resolution (weighed by `field.detail`). A copy through the raster alone (panorama to
    raster to panorama) kept about 60 % of the fine detail: at 1024x512 the per-pixel synthesis
    of a plain wall or floor came out at 0.42-0.58 of the truth's detail, 0.74-0.88 with it. The
    lookup keeps a single pixel's grain (`planeraster.sample_points_keeping_grain`): a plain
    bilinear lookup kept 0.64-0.81 of the truth's pixel detail at 1024x512 on composed floors,
    this one 0.87-1.03, for 0.00-0.02 of structure (the copy's grain is its own, not the
    truth's). Sharper lookups that move or blur the copy did worse. A shifted copy's detail is
    held within the grain's spread (`_grain_bound`)."""
    maps = panorama.maps
    r, c = _nearest_cells(raster, plane.points)
    sel = np.flatnonzero(field.copied[r, c])
    if not len(sel):
        return rho
    t = field.shift[r[sel], c[sel]] * raster.cell
    source = plane.points[sel] + t[:, :1] * raster.v + t[:, 1:] * raster.u
    copy, weight = planeraster.sample_points_keeping_grain(source, panorama.rho, panorama.shows(plane.surface),
                                                           frame=maps.frame)
    coarse = planeraster.sample_raster(raster, field.coarse, source)
    ok = weight > 0.5
    detail = copy[ok] - coarse[ok]
    gain = field.detail[r[sel], c[sel]][ok]
    composed = field.composed[r[sel], c[sel]][ok]
    if composed.any():
        gain[composed] *= _grain_bound(detail[composed], coarse[ok][composed])
    out = rho.copy()
    out[sel[ok]] += gain[:, None] * detail
    return out


def _grain_bound(detail: np.ndarray, coarse: np.ndarray) -> np.ndarray:
    """(N,) the factor, at most 1, that scales each copy's `detail` (N, 3) down where its luminance
    relative to `coarse` (N, 3) lies farther from the median of all of theirs than `_GRAIN_SPREAD`
    times their robust spread (the median absolute deviation, scaled to a standard deviation)."""
    relative = (detail @ LUMA) / np.maximum(coarse @ LUMA, 1e-9)
    deviation = np.abs(relative - np.median(relative))
    bound = _GRAIN_SPREAD * 1.4826 * float(np.median(deviation))
    return np.minimum(1.0, bound / np.maximum(deviation, 1e-12))
