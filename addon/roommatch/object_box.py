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

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import DimredError
from ..geometry.resample import resample_axis
from ..segmentation.grabcut import segment_object
from ..segmentation.masks import dilate
from .projection import click_directions

_WORKING_WIDTH = 1024
_WINDOW = 0.12  # half the window's side, as a share of the panorama's width (43 degrees)
_REFINE_BAND = 0.12  # the second pass's band, as a share of the object's size in pixels
_SEED = 1.5  # px radius of the seed disc at the click, on the coarsest copy the segmentation halves to
_COARSEST_BAND = 16  # the widest band `segment_object` decides without halving
_MIN_PIXELS = 30
_STEPS = np.array([0.05, 0.05, 0.1, 0.1, 0.1, np.radians(5.0)])  # metres, log-size, radians
_FINEST = 1.0 / 32.0  # of the first steps
_MAX_EVALUATIONS = 600


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
        w, d = self.size[:2] / 2.0
        local = np.array([[-w, -d], [w, -d], [w, d], [-w, d]])
        c, s = np.cos(self.turn), np.sin(self.turn)
        xy = local @ np.array([[c, s], [-s, c]]) + self.bottom[:2]
        z = np.full((4, 1), self.bottom[2])
        return np.concatenate([np.concatenate([xy, z], axis=1), np.concatenate([xy, z + self.size[2]], axis=1)])

    def summary(self) -> dict[str, Any]:
        return {"bottom_centre": np.round(self.bottom, 4).tolist(), "size_m": np.round(self.size, 4).tolist(),
                "turn_deg": round(float(np.degrees(self.turn)), 2), "agreement": round(self.agreement, 4),
                "outline_pixels": self.outline_pixels}


def box_from_click(panorama: np.ndarray, click: tuple[float, float], *, click_size: tuple[int, int],
                   probe: np.ndarray, floor_z: float = 0.0, rotation: np.ndarray | None = None) -> BoxFit:
    """The box proxy of the object clicked at `click` (x, y) on a `click_size` (W, H) panorama;
    DimredError when the photograph shows no object there standing on the floor."""
    probe = np.asarray(probe, dtype=np.float64)
    camera = float(probe[2] - floor_z)
    if not camera > 0.0:
        raise DimredError(f"the probe centre is not above the floor ({camera:.3g} m): match the room first")
    image = np.asarray(panorama, dtype=np.float32)
    width = min(_WORKING_WIDTH, image.shape[1])
    height = width // 2
    image = resample_axis(resample_axis(image, height, axis=0), width, axis=1)
    x, y = (np.asarray(click, dtype=np.float64) + 0.5) * (width / click_size[0], height / click_size[1]) - 0.5
    half = int(_WINDOW * width)
    col0, row0 = round(float(x)) - half, max(0, round(float(y)) - half)
    rows = np.arange(row0, min(height, round(float(y)) + half + 1))
    cols = np.arange(col0, col0 + 2 * half + 1)
    window = image[rows[:, None], np.mod(cols, width)[None, :]]
    # Pixel directions in the probe's frame, the window's columns as the panorama's.
    directions = click_directions(np.stack(np.broadcast_arrays(cols[None, :], rows[:, None]), axis=-1),
                                  width, height, rotation)
    band = half // 2
    # The segmentation decides a wide band on halved copies first: the seed must survive them.
    halvings = max(0, int(np.ceil(np.log2(band / _COARSEST_BAND))))
    seed = (rows[:, None] - y) ** 2 + (cols[None, :] - x) ** 2 <= (_SEED * 2**halvings) ** 2
    shown = _segment(window, seed, band)
    points = _floor_points(shown, directions, camera)
    if len(points) < 3:
        raise DimredError(f"no object standing on the floor is seen at ({click[0]:g}, {click[1]:g}): click inside "
                          "an object whose foot the panorama shows")
    start = _first_box(points, shown, directions, camera)
    params, agreement = _search(start, shown, directions, camera)
    return BoxFit(bottom=np.array([probe[0] + params[0], probe[1] + params[1], floor_z]),
                  size=np.exp(params[2:5]), turn=float(params[5]), agreement=agreement,
                  outline_pixels=int(shown.sum()))


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
    near = np.nanmax(np.minimum(t1, t2), axis=-1)
    far = np.nanmin(np.maximum(t1, t2), axis=-1)
    return far >= np.maximum(near, 0.0)


def _segment(window: np.ndarray, seed: np.ndarray, band: int) -> np.ndarray:
    """The object at the seed: segmented in a `band` half the window wide around the seed (its
    background sampled beyond that band; no pull towards the seed's side, which would keep the
    object as small as the seed), then again in a narrow band around what was found."""
    if float(np.ptp(window)) <= 1e-6 * max(float(window.max()), 1e-12):
        raise DimredError("the panorama is flat around the click: there is no object to outline")
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


def _search(params: np.ndarray, shown: np.ndarray, directions: np.ndarray, camera: float) -> tuple[np.ndarray, float]:
    """Coordinate search on the box's six parameters for the largest intersection over union."""
    def score(p: np.ndarray) -> float:
        box = silhouette(_centred(p), directions, camera)
        return float(np.count_nonzero(box & shown)) / max(float(np.count_nonzero(box | shown)), 1.0)

    best = score(params)
    steps = _STEPS.copy()
    evaluations = 1
    while steps[0] > _STEPS[0] * _FINEST and evaluations < _MAX_EVALUATIONS:
        improved = False
        for i in range(len(params)):
            for sign in (1.0, -1.0):
                trial = params.copy()
                trial[i] += sign * steps[i]
                value = score(trial)
                evaluations += 1
                if value > best:
                    params, best, improved = trial, value, True
                    break
        if not improved:
            steps /= 2.0
    return _centred(params), best
