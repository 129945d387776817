"""Object from Photo: one click inside an object standing on the floor gives its box proxy.

The panorama around the click is segmented (`segmentation.grabcut`, seeded by a small disc at
the click, the band reaching across the whole window) and the segment holding the click kept.
Its lowest pixel in each column is where the object meets the floor: taken down to the floor
from the probe, those points give the box's first place, turn and footprint; its topmost pixels
its first height. Then the box's centre, width, depth, height and turn are searched so that its
silhouette, traced from the probe, shares the most pixels with the outline (intersection over
union, the agreement reported).
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import DimredError
from ..geometry.resample import resample_axis
from ..segmentation.grabcut import segment_object
from ..segmentation.masks import dilate
from .polygon import contains
from .projection import click_directions, project

_WORKING_WIDTH = 1024
_WINDOW = 0.12  # half the window's side, as a share of the panorama's width (43 degrees)
_REFINE_BAND = 0.12  # the second pass's band, as a share of the object's size in pixels
_SHADING = 0.7  # the share of the luminance divided out of the image the segmentation sees
_LUMINANCE = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
_PROXY_BAND = 0.3  # the first pass's band around a proxy, as a share of its size in pixels
_SEED = 1.5  # px radius of the seed disc at the click, on the coarsest copy the segmentation halves to
_COARSEST_BAND = 16  # the widest band `segment_object` decides without halving
_MIN_PIXELS = 30
_STEPS = np.array([0.05, 0.05, 0.1, 0.1, 0.1, np.radians(5.0)])  # metres, log-size, radians
# The search's moves: each parameter alone, and one size traded against another (a deeper, lower
# box shows much the same outline: alone, neither move would be taken).
_DIRECTIONS = np.concatenate([np.diag(_STEPS), _STEPS * np.array([[0, 0, 0, 1, -1, 0], [0, 0, 1, 0, -1, 0],
                                                                   [0, 0, 1, -1, 0, 0]])])
_FINEST = 1.0 / 32.0  # the last steps, a share of the first
_MAX_EVALUATIONS = 600
_PULL = 0.95  # a first box through a wall moves this much nearer the probe a step, and its depth shrinks
_PULLS = 40


@dataclass(frozen=True)
class BoxFit:
    """A box standing on the floor: bottom centre (x, y, floor z), size (width along the turn,
    depth across it, height), turn about the vertical (radians), and how well its silhouette
    agrees with the photographed outline (shared over united pixels)."""

    bottom: np.ndarray
    size: np.ndarray
    turn: float
    agreement: float
    outline_pixels: int

    def corners(self) -> np.ndarray:
        """(8, 3) world corners: the bottom four counter-clockwise, then the top four."""
        xy = _footprint(self.bottom[:2], self.size[:2], self.turn)
        z = np.full((4, 1), self.bottom[2])
        return np.concatenate([np.concatenate([xy, z], axis=1), np.concatenate([xy, z + self.size[2]], axis=1)])

    def summary(self) -> dict[str, Any]:
        return {"bottom_centre": np.round(self.bottom, 4).tolist(), "size_m": np.round(self.size, 4).tolist(),
                "turn_deg": round(float(np.degrees(self.turn)), 2), "agreement": round(self.agreement, 4),
                "outline_pixels": self.outline_pixels}


def box_from_click(panorama: np.ndarray, click: tuple[float, float], *, click_size: tuple[int, int],
                   probe: np.ndarray, floor_z: float = 0.0, rotation: np.ndarray | None = None,
                   inside: np.ndarray | None = None) -> BoxFit:
    """The box proxy of the object clicked at `click` (x, y) on a `click_size` (W, H) panorama,
    its footprint within the floor polygon `inside` ((n, 2) world) where one is given;
    DimredError when the photograph shows no object there standing on the floor."""
    return box_in_outline(outline_at(panorama, click, click_size=click_size, probe=probe, floor_z=floor_z,
                                     rotation=rotation, inside=inside), click)


def outline_at(panorama: np.ndarray, click: tuple[float, float], *, click_size: tuple[int, int], probe: np.ndarray,
               floor_z: float = 0.0, rotation: np.ndarray | None = None,
               inside: np.ndarray | None = None) -> Outline:
    """The outline of the object seen at `click` (x, y) on a `click_size` (W, H) panorama, segmented
    from a seed there; DimredError when the photograph sets too little apart."""
    probe, camera = _camera(probe, floor_z)
    view = _View.around(panorama, click, click_size, rotation, _WINDOW)
    band = view.half // 2
    # The segmentation decides a wide band on halved copies first: the seed must survive them.
    halvings = max(0, int(np.ceil(np.log2(band / _COARSEST_BAND))))
    seed = (view.rows[:, None] - view.y) ** 2 + (view.cols[None, :] - view.x) ** 2 <= (_SEED * 2**halvings) ** 2
    return Outline(_segment(view.image, seed, band), view.directions, camera, probe, floor_z, inside,
                   _rotation(rotation))


def box_in_outline(outline: Outline, click: tuple[float, float]) -> BoxFit:
    """The box fitted to `outline`, the object clicked at `click`; DimredError when its foot is not seen."""
    points = _floor_points(outline.shown, outline.directions, outline.camera)
    if len(points) < 3:
        raise DimredError(f"no object standing on the floor is seen at ({click[0]:g}, {click[1]:g}): click inside "
                          "an object whose foot the panorama shows")
    return _fitted(_first_box(points, outline.shown, outline.directions, outline.camera), outline)


def refit_box(panorama: np.ndarray, corners: np.ndarray, *, probe: np.ndarray, floor_z: float = 0.0,
              rotation: np.ndarray | None = None, inside: np.ndarray | None = None) -> BoxFit:
    """A box proxy (`corners` (8, 3) world, standing upright) refitted to the object's outline in
    the photograph: its place, turn and each of its three sizes (Align to Photo keeps the
    proportions). DimredError when the corners are no upright box or the photograph shows
    nothing there."""
    probe, camera = _camera(probe, floor_z)
    params = _box_params(np.asarray(corners, dtype=np.float64), probe, floor_z)
    centre = np.array([params[0], params[1], -camera + 0.5 * np.exp(params[4])])
    height, width = panorama.shape[:2]
    at = project(centre, width, height, rotation)
    reach = float(np.linalg.norm(np.exp(params[2:5]))) / max(float(np.linalg.norm(centre)), 1e-9)
    view = _View.around(panorama, tuple(at), (width, height), rotation, max(_WINDOW, reach / np.pi))
    proxy = silhouette(params, view.directions, camera)
    if proxy.sum() < _MIN_PIXELS:
        raise DimredError("the box is too small in the panorama to refit it")
    extent = max(np.ptp(np.nonzero(proxy)[0]), np.ptp(np.nonzero(proxy)[1]))
    # A band as wide as a box modelled by eye may be off (its height by a fifth, say).
    shown = _segment(view.image, proxy, max(2, int(_PROXY_BAND * extent)))
    # From the proxy as modelled, and from the outline's own first box: a turn off by several
    # degrees can hold the search in a nearby optimum.
    outline = Outline(shown, view.directions, camera, probe, floor_z, inside, _rotation(rotation))
    fits = [_fitted(_front(params), outline)]
    points = _floor_points(shown, view.directions, camera)
    if len(points) >= 3:
        fits.append(_fitted(_first_box(points, shown, view.directions, camera), outline))
    return max(fits, key=lambda fit: fit.agreement)


@dataclass(frozen=True)
class _View:
    """A square window of the panorama at the working width around pixel (x, y): its image, its
    rows and columns (the columns may run past the seam) and its pixels' directions."""

    image: np.ndarray
    rows: np.ndarray
    cols: np.ndarray
    directions: np.ndarray
    x: float
    y: float
    half: int

    @classmethod
    def around(cls, panorama: np.ndarray, at: tuple[float, float], size: tuple[int, int],
               rotation: np.ndarray | None, share: float) -> _View:
        image = np.asarray(panorama, dtype=np.float32)
        width = min(_WORKING_WIDTH, image.shape[1])
        height = width // 2
        image = resample_axis(resample_axis(image, height, axis=0), width, axis=1)
        x, y = (np.asarray(at, dtype=np.float64) + 0.5) * (width / size[0], height / size[1]) - 0.5
        half = int(min(share, 0.45) * width)
        rows = np.arange(max(0, round(float(y)) - half), min(height, round(float(y)) + half + 1))
        cols = np.arange(round(float(x)) - half, round(float(x)) + half + 1)
        directions = click_directions(np.stack(np.broadcast_arrays(cols[None, :], rows[:, None]), axis=-1),
                                      width, height, rotation)
        return cls(image[rows[:, None], np.mod(cols, width)[None, :]], rows, cols, directions, float(x), float(y),
                   half)


def _camera(probe: np.ndarray, floor_z: float) -> tuple[np.ndarray, float]:
    probe = np.asarray(probe, dtype=np.float64)
    camera = float(probe[2] - floor_z)
    if not camera > 0.0:
        raise DimredError(f"the probe centre is not above the floor ({camera:.3g} m): match the room first")
    return probe, camera


def _rotation(rotation: np.ndarray | None) -> np.ndarray:
    return np.eye(3) if rotation is None else np.asarray(rotation, dtype=np.float64)


@dataclass(frozen=True)
class Outline:
    """What a proxy is fitted to: the outline (h, w) over a window, its pixels' directions from
    the probe, the probe's height above the floor, the probe, the floor's z, the floor polygon
    ((n, 2) world) the proxy must stand in, if any, and the panorama's rotation (3, 3)."""

    shown: np.ndarray
    directions: np.ndarray
    camera: float
    probe: np.ndarray
    floor_z: float
    inside: np.ndarray | None
    rotation: np.ndarray

    def cropped(self) -> tuple[np.ndarray, np.ndarray]:
        """The outline and its directions over its bounding box grown by half its size each way:
        a proxy whose silhouette reaches past it agrees less anyway."""
        rows, cols = np.nonzero(self.shown)
        pad_r, pad_c = (np.ptp(rows) + 1) // 2, (np.ptp(cols) + 1) // 2
        crop = (slice(max(0, rows.min() - pad_r), rows.max() + pad_r + 1),
                slice(max(0, cols.min() - pad_c), cols.max() + pad_c + 1))
        return self.shown[crop], self.directions[crop]

    def room(self) -> np.ndarray | None:
        """The floor polygon from the probe, or None."""
        return None if self.inside is None else np.asarray(self.inside, dtype=np.float64) - self.probe[:2]


def _fitted(start: np.ndarray, outline: Outline) -> BoxFit:
    shown, directions = outline.cropped()
    params, agreement = _search(start, shown, directions, outline.camera, outline.room())
    probe = outline.probe
    return BoxFit(bottom=np.array([probe[0] + params[0], probe[1] + params[1], outline.floor_z]),
                  size=np.exp(params[2:5]), turn=float(params[5]), agreement=agreement,
                  outline_pixels=int(outline.shown.sum()))


def _footprint(centre: np.ndarray, size: np.ndarray, turn: float) -> np.ndarray:
    """(4, 2) a box's bottom corners counter-clockwise: centre (2,), width and depth, turn."""
    w, d = np.asarray(size[:2], dtype=np.float64) / 2.0
    c, s = np.cos(turn), np.sin(turn)
    return np.array([[-w, -d], [w, -d], [w, d], [-w, d]]) @ np.array([[c, s], [-s, c]]) + centre


def _box_params(corners: np.ndarray, probe: np.ndarray, floor_z: float) -> np.ndarray:
    """`silhouette`'s parameters of an upright box given by its 8 corners (any order)."""
    if corners.shape != (8, 3):
        raise DimredError(f"a box has 8 corners, this mesh {len(corners)}: Fit Box works on box proxies only")
    order = np.argsort(corners[:, 2])
    bottom, top = corners[order[:4]], corners[order[4:]]
    tall = float(top[:, 2].mean() - bottom[:, 2].mean())
    centre = bottom[:, :2].mean(axis=0)
    spokes = bottom[:, :2] - centre
    ring = bottom[np.argsort(np.arctan2(spokes[:, 1], spokes[:, 0])), :2]  # round the footprint
    side, other = ring[1] - ring[0], ring[2] - ring[1]
    width, depth = float(np.linalg.norm(side)), float(np.linalg.norm(other))
    flat = np.ptp(bottom[:, 2]) <= 1e-3 * max(tall, 1e-9) + 1e-6 and np.ptp(top[:, 2]) <= 1e-3 * tall + 1e-6
    # A rectangle: sides at right angles, opposite sides equal; the top straight above it.
    above = np.linalg.norm(top[:, None, :2] - ring[None, :, :], axis=2).min(axis=1)
    square = (abs(float(side @ other)) <= 1e-3 * width * depth + 1e-9
              and np.allclose(ring[2] - ring[3], side, atol=1e-4 * (width + depth))
              and bool(np.all(above <= 1e-3 * (width + depth))))
    if not (tall > 0 and width > 0 and depth > 0 and flat and square):
        raise DimredError("the proxy is not an upright box: Fit Box works on box proxies only")
    if abs(float(bottom[:, 2].mean()) - floor_z) > 0.02:
        raise DimredError(f"the box stands {bottom[:, 2].mean() - floor_z:+.3f} m off the floor: put it on the floor")
    turn = float(np.arctan2(side[1], side[0]))
    return np.array([centre[0] - probe[0], centre[1] - probe[1], np.log(width), np.log(depth), np.log(tall), turn])


def silhouette(params: np.ndarray, directions: np.ndarray, camera: float) -> np.ndarray:
    """(h, w) bool: the rays `directions` (h, w, 3) from the probe that hit the box `params`
    (bottom centre x, y from the probe, log width, log depth, log height, turn), its bottom
    `camera` below the probe."""
    cx, cy, lw, ld, lh, turn = params
    half = 0.5 * np.exp(np.array([lw, ld, lh]))
    c, s = np.cos(turn), np.sin(turn)
    # The probe and the rays in the box's frame (centre at the origin, axes along its sides).
    origin = np.array([-cx * c - cy * s, cx * s - cy * c, camera - half[2]])
    d = directions
    local = np.stack([d[..., 0] * c + d[..., 1] * s, -d[..., 0] * s + d[..., 1] * c, d[..., 2]], axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-half - origin) / local
        t2 = (half - origin) / local
    low, high = np.minimum(t1, t2), np.maximum(t1, t2)
    # fmax and fmin skip a NaN (a ray lying in a slab's plane) as nanmax does; unrolled over the axes, faster
    near = np.fmax(np.fmax(low[..., 0], low[..., 1]), low[..., 2])
    far = np.fmin(np.fmin(high[..., 0], high[..., 1]), high[..., 2])
    return far >= np.maximum(near, 0.0)


def _segment(window: np.ndarray, seed: np.ndarray, band: int) -> np.ndarray:
    """The object at the seed (a disc at a click, or a proxy's silhouette): segmented in a wide
    `band` around the seed (its background sampled beyond that band; no pull towards the seed's
    side, which would keep the object as small as the seed), then again in a narrow band around
    what was found."""
    if float(np.ptp(window)) <= 1e-6 * max(float(window.max()), 1e-12):
        raise DimredError("the panorama is flat around the click: there is no object to outline")
    # Shading compressed: a box's lit top and its sides in shade are one material.
    luminance = np.maximum(window @ _LUMINANCE, 1e-6)[..., None]
    window = window / luminance ** _SHADING
    part = _holding(segment_object(window, seed, band=band, prior=0.0).object, seed)
    if part.sum() >= _MIN_PIXELS:
        extent = max(np.ptp(np.nonzero(part)[0]), np.ptp(np.nonzero(part)[1]))
        part = _holding(segment_object(window, part, band=max(2, int(_REFINE_BAND * extent))).object, seed)
    if part.sum() < _MIN_PIXELS:
        raise DimredError(f"the photograph sets {int(part.sum())} pixels apart at the click: too few to fit a box "
                          "to; click inside the object")
    return part


def _holding(found: np.ndarray, seed: np.ndarray) -> np.ndarray:
    """The connected part of `found` that holds the seed, grown from it."""
    part = seed & found
    while part.any():
        grown = dilate(part, 2) & found
        if grown.sum() == part.sum():
            break
        part = grown
    return part


def _floor_points(shown: np.ndarray, directions: np.ndarray, camera: float) -> np.ndarray:
    """(m, 2) floor points (from the probe) under the object's lowest pixel in each column."""
    columns = np.flatnonzero(shown.any(axis=0))
    lowest = shown.shape[0] - 1 - np.argmax(shown[::-1, columns], axis=0)
    inside = lowest < shown.shape[0] - 1  # an object cut off by the window's bottom has no foot there
    d = directions[lowest[inside], columns[inside]]
    below = d[:, 2] < -np.sin(np.radians(2.0))
    return d[below, :2] * (camera / -d[below, 2:3])


def _first_box(points: np.ndarray, shown: np.ndarray, directions: np.ndarray, camera: float) -> np.ndarray:
    """The first box in front-face parameters (`_centred`): its foot's seen side fixed, as deep
    as it is wide, as tall as the outline's top above that side."""
    front = points.mean(axis=0)
    spread = np.cov((points - front).T)
    axis = np.linalg.eigh(spread)[1][:, 1]
    width = max(float(np.ptp(points @ axis)), 0.1)
    columns = shown.any(axis=0)
    top = directions[np.argmax(shown, axis=0)[columns], np.flatnonzero(columns)]
    rise = np.max(top[:, 2] / np.maximum(np.linalg.norm(top[:, :2], axis=1), 1e-9))
    tall = max(camera + float(np.linalg.norm(front)) * rise, 0.1)
    return np.array([front[0], front[1], np.log(width), np.log(width), np.log(tall),
                     float(np.arctan2(axis[1], axis[0]))])


def _front(params: np.ndarray) -> np.ndarray:
    """Front-face parameters of box parameters (the inverse of `_centred`)."""
    x, y, lw, ld, lh, turn = params
    axes = np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    extents = np.exp([lw, ld])
    away = np.array([x, y]) / max(float(np.hypot(x, y)), 1e-9)
    k = int(np.argmax(np.abs(axes @ away)))
    front = np.array([x, y]) - axes[k] * np.sign(axes[k] @ away) * extents[k] / 2.0
    return np.array([front[0], front[1], lw, ld, lh, turn])


def _centred(front: np.ndarray) -> np.ndarray:
    """Box parameters (bottom centre) from front-face parameters: the bottom centre of the side
    facing the probe instead of the box's, so that a change of depth keeps that side in place."""
    x, y, lw, ld, lh, turn = front
    axes = np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    extents = np.exp([lw, ld])
    away = np.array([x, y]) / max(float(np.hypot(x, y)), 1e-9)
    k = int(np.argmax(np.abs(axes @ away)))
    # Half the box's extent along its axis that points away from the probe, behind the front.
    centre = np.array([x, y]) + axes[k] * np.sign(axes[k] @ away) * extents[k] / 2.0
    return np.array([centre[0], centre[1], lw, ld, lh, turn])


def _search(params: np.ndarray, shown: np.ndarray, directions: np.ndarray, camera: float,
            room: np.ndarray | None) -> tuple[np.ndarray, float]:
    """Coordinate search on the box's six parameters for the largest intersection over union,
    its footprint within `room` ((n, 2) from the probe) where given."""
    def score(p: np.ndarray) -> float:
        centred = _centred(p)
        if room is not None and not all(contains(room, corner) for corner in
                                        _footprint(centred[:2], np.exp(centred[2:4]), centred[5])):
            return -1.0  # through a wall: never taken
        return agreement(silhouette(centred, directions, camera), shown)

    best = score(params)
    for _ in range(_PULLS):  # a first box through a wall is drawn towards the probe, then shrunk
        if best >= 0.0:
            break
        params = params * np.array([_PULL, _PULL, 1.0, 1.0, 1.0, 1.0]) - np.array([0, 0, 0, 1 - _PULL, 0, 0])
        best = score(params)
    params, best = climb(score, params, best, _DIRECTIONS, budget=_MAX_EVALUATIONS)
    return _centred(params), best


def agreement(silhouette: np.ndarray, shown: np.ndarray) -> float:
    """Pixels a proxy's `silhouette` and the `shown` outline share, over the pixels either covers."""
    return float(np.count_nonzero(silhouette & shown)) / max(float(np.count_nonzero(silhouette | shown)), 1.0)


def climb(score: Callable[[np.ndarray], float], params: np.ndarray, best: float, directions: np.ndarray, *,
          budget: int) -> tuple[np.ndarray, float]:
    """Coordinate search from `params` (scoring `best`) for the largest `score`: each move of
    `directions` tried both ways, the first that gains taken; the moves halved where none gains,
    down to `_FINEST` of the first, within `budget` evaluations."""
    scale = 1.0
    evaluations = 1
    while scale > _FINEST and evaluations < budget:
        improved = False
        for direction in directions:
            for sign in (1.0, -1.0):
                trial = params + sign * scale * direction
                value = score(trial)
                evaluations += 1
                if value > best:
                    params, best, improved = trial, value, True
                    break
        if not improved:
            scale /= 2.0
    return params, best
