"""Object from Photo's proxies: from one click, a box, or a stepped box where the outline shows a
part standing higher than the rest, carved to the outline where neither agrees with it; from the
object's contact points, a prism over them.

One click: the box of `object_box`, then the same box cut in two along its width or its depth,
each part with its own height and the cut's place searched (an armchair's back behind its seat);
the stepped box is kept where it agrees with the outline by `_STEP_GAIN` more, so a box stays a
box. Where the one kept agrees below `_CARVE_BELOW` (curved arms, a sloping back), it is grown
to cover the outline and carved into its one-view hull (`hull`), kept where that agrees by
`_CARVE_GAIN` more. Contact points: clicked where the object meets the floor, in order round it, they give the
footprint polygon on the floor; the panorama is segmented from a seed above the footprint and the
prism's height is the one whose silhouette agrees best with the outline.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import DimredError
from .clicks import ObjectClicks
from .fit import check_simple, unit_floor_points
from .hull import Hull, Wedges, carve, traced, vertical_columns
from .object_box import BoxFit, Outline, agreement, box_in_outline, climb, outline_at, silhouette
from .projection import project
from .solids import Solid, inside_polygon, prism_silhouette

_STEP_GAIN = 0.01  # the agreement a stepped box must add to the box's to be kept
# The stepped box's moves: place (m), log width and depth, turn (rad), the cut (logit), log heights.
_STEP_MOVES = np.diag([0.05, 0.05, 0.1, 0.1, np.radians(5.0), 0.5, 0.1, 0.1])
_STEP_BUDGET = 300
_CARVE_BELOW = 0.95  # a box or stepped box agreeing this well with the outline is kept as it is
_CARVE_GAIN = 0.02  # the agreement a carved proxy must add to the box's or stepped box's to be kept
_GROWTH_COST = 0.05  # the agreement a carved proxy's base may give up per share of volume it grows by
_GROW_MOVES = np.diag([0.03, 0.03, 0.03, 0.03, 0.05])  # each side of the base (m), its heights (log)
_GROW_BUDGET = 200
_SEED_HEIGHT = 0.25  # metres above the floor where the footprint's seed is
_HEIGHTS = np.log(np.geomspace(0.05, 4.0, 40))  # the prism heights tried first (log metres)
_HEIGHT_MOVES = np.array([[0.05]])
_HEIGHT_BUDGET = 40


@dataclass(frozen=True)
class ObjectProxy:
    """A proxy fitted to an object's outline: its solid, its kind ("box", "stepped box", "carved
    box", "carved stepped box" or "footprint prism"), its size (width, depth, height in metres; a
    footprint's extent along x and y), how well its silhouette agrees with the outline (shared
    over united pixels), the outline's pixels, and what the kind adds to the summary."""

    solid: Solid | Hull
    kind: str
    size: np.ndarray
    agreement: float
    outline_pixels: int
    details: dict[str, Any]

    def summary(self) -> dict[str, Any]:
        return {"shape": self.kind, **self.details, "agreement": round(self.agreement, 4),
                "outline_pixels": self.outline_pixels}


def object_proxy(panorama: np.ndarray, obj: ObjectClicks, *, click_size: tuple[int, int], probe: np.ndarray,
                 floor_z: float = 0.0, rotation: np.ndarray | None = None,
                 inside: np.ndarray | None = None) -> ObjectProxy:
    """The proxy of a click file's object: from its click or from its footprint."""
    where = {"click_size": click_size, "probe": probe, "floor_z": floor_z, "rotation": rotation, "inside": inside}
    if obj.click is not None:
        return object_from_click(panorama, obj.click, **where)
    return object_from_footprint(panorama, obj.footprint, **where)


def object_from_click(panorama: np.ndarray, click: tuple[float, float], *, click_size: tuple[int, int],
                      probe: np.ndarray, floor_z: float = 0.0, rotation: np.ndarray | None = None,
                      inside: np.ndarray | None = None) -> ObjectProxy:
    """The proxy of the object clicked at `click` (x, y) on a `click_size` (W, H) panorama: its box,
    or a stepped box where that agrees better with its outline, carved where neither agrees well;
    within the floor polygon `inside` ((n, 2) world) where given. DimredError when the photograph
    shows no object standing there."""
    outline = outline_at(panorama, click, click_size=click_size, probe=probe, floor_z=floor_z, rotation=rotation,
                         inside=inside)
    box = box_in_outline(outline, click)
    proxy = ObjectProxy(_box_solid(box), "box", box.size, box.agreement, box.outline_pixels, box.summary())
    parts = np.array([[box.bottom[0] - probe[0], box.bottom[1] - probe[1], *np.log(box.size), box.turn]])
    stepped, step_parts = max((_stepped(box, outline, axis) for axis in (0, 1)), key=lambda fit: fit[0].agreement)
    if stepped.agreement >= box.agreement + _STEP_GAIN:
        proxy = dataclasses.replace(stepped, details={**stepped.details, "box_agreement": round(box.agreement, 4)})
        parts = step_parts
    if proxy.agreement >= _CARVE_BELOW or not vertical_columns(outline):
        return proxy
    carved = _carved(proxy, parts, outline)
    return carved if carved.agreement >= proxy.agreement + _CARVE_GAIN else proxy


def object_from_footprint(panorama: np.ndarray, footprint: tuple[tuple[float, float], ...], *,
                          click_size: tuple[int, int], probe: np.ndarray, floor_z: float = 0.0,
                          rotation: np.ndarray | None = None, inside: np.ndarray | None = None) -> ObjectProxy:
    """The prism over the contact points `footprint` (x, y clicks on a `click_size` (W, H)
    panorama, in order round the object), its height fitted to the object's outline; DimredError
    naming the click when they give no footprint on the floor (within `inside`, (n, 2) world)."""
    width, height = click_size
    points = np.asarray(footprint, dtype=np.float64).reshape(-1, 2)
    if len(points) < 3:
        raise DimredError(f"a footprint needs 3 or more contact points, {len(points)} clicked")
    names = [f"contact point {i}" for i in range(len(points))]
    for (x, y), name in zip(points, names, strict=True):
        if not (-0.5 <= x < width - 0.5 and -0.5 <= y <= height - 0.5):
            raise DimredError(f"{name} ({x:g}, {y:g}) lies outside the {width} × {height} panorama")
    probe = np.asarray(probe, dtype=np.float64)
    camera = float(probe[2] - floor_z)
    if not camera > 0.0:
        raise DimredError(f"the probe centre is not above the floor ({camera:.3g} m): match the room first")
    unit = unit_floor_points(points, width, height, rotation, names)
    check_simple(unit, "the footprint", hint="click the object's contact points in order round it")
    corners = unit * camera
    if inside is not None:
        room = np.asarray(inside, dtype=np.float64) - probe[:2]
        outside = np.flatnonzero(~inside_polygon(corners, room))
        if outside.size:
            x, y = points[outside[0]]
            raise DimredError(f"{names[outside[0]]} ({x:g}, {y:g}) lies outside the room's floor")
    # A point inside the object low above its footprint shows the object, whatever stands on it.
    seed = np.append(corners.mean(axis=0), _SEED_HEIGHT - camera)
    at = tuple(project(seed, width, height, rotation))
    outline = outline_at(panorama, at, click_size=click_size, probe=probe, floor_z=floor_z, rotation=rotation,
                         inside=inside)
    shown, directions = outline.cropped()

    def score(log_height: np.ndarray) -> float:
        return agreement(prism_silhouette(corners, float(np.exp(log_height[0])), directions, camera), shown)

    scores = [score(np.array([h])) for h in _HEIGHTS]
    start = int(np.argmax(scores))
    log_height, fitted = climb(score, np.array([_HEIGHTS[start]]), scores[start], _HEIGHT_MOVES, budget=_HEIGHT_BUDGET)
    tall = float(np.exp(log_height[0]))
    solid = Solid.prism(corners + probe[:2], floor_z, tall)
    details = {"footprint_m": np.round(corners + probe[:2], 4).tolist(), "height_m": round(tall, 4)}
    size = np.append(np.ptp(corners, axis=0), tall)
    return ObjectProxy(solid, "footprint prism", size, fitted, int(outline.shown.sum()), details)


def _box_solid(box: BoxFit) -> Solid:
    return Solid.prism(box.corners()[:4, :2], float(box.bottom[2]), float(box.size[2]))


def _carved(proxy: ObjectProxy, parts: np.ndarray, outline: Outline) -> ObjectProxy:
    """The one-view hull of `outline` in the box or stepped box `proxy` (its `parts`, `silhouette`'s
    parameters), grown side by side and in height where its silhouette leaves the outline's
    pixels out, for as long as the agreement gained outweighs the volume added."""
    shown, directions = outline.cropped()
    small = dataclasses.replace(outline, shown=shown, directions=directions)
    wedges = Wedges.of(small)
    room = outline.room()
    volume = _volume(parts)

    def score(grow: np.ndarray) -> float:
        if (grow < 0.0).any():
            return -1.0
        boxes = _grown(parts, grow)
        if room is not None and not all(inside_polygon(_part_footprint(b), room).all() for b in boxes):
            return -1.0  # through a wall: never taken
        base = np.logical_or.reduce([silhouette(b, directions, outline.camera) for b in boxes])
        return agreement(wedges.shown & base, shown) - _GROWTH_COST * (_volume(boxes) / volume - 1.0)

    start = np.zeros(5)
    grow, _ = climb(score, start, score(start), _GROW_MOVES, budget=_GROW_BUDGET)
    boxes = _grown(parts, grow)
    hull = carve(small, wedges, boxes)
    if hull is None:
        return proxy
    fitted = agreement(traced(hull, small), shown)
    turn = boxes[0, 5]
    frame = np.array([[np.cos(turn), np.sin(turn), 0.0], [-np.sin(turn), np.cos(turn), 0.0], [0.0, 0.0, 1.0]])
    size = np.ptp(hull.vertices @ frame.T, axis=0)
    fit = {key: value for key, value in proxy.details.items() if key not in ("agreement", "box_agreement")}
    base = {"shape": proxy.kind, **fit, "agreement": round(proxy.agreement, 4),
            "grown_m": np.round(grow[:4], 4).tolist(), "heights_scaled": round(float(np.exp(grow[4])), 3)}
    details = {"base": base, "triangles": len(hull.triangles),
               "box_agreement": proxy.details.get("box_agreement", round(proxy.agreement, 4))}
    return ObjectProxy(hull, f"carved {proxy.kind}", size, fitted, proxy.outline_pixels, details)


def _grown(parts: np.ndarray, grow: np.ndarray) -> np.ndarray:
    """The parts (side by side, one turn) with the sides on their union's outline moved out by
    `grow[:4]` metres (width's low and high side, depth's low and high side) and every height
    scaled by exp(`grow[4]`)."""
    turn = parts[0, 5]
    axes = np.array([[np.cos(turn), np.sin(turn)], [-np.sin(turn), np.cos(turn)]])
    centre = parts[:, :2] @ axes.T
    half = 0.5 * np.exp(parts[:, 2:4])
    low, high = centre - half, centre + half
    low = low - np.where(low <= low.min(axis=0) + 1e-9, grow[[0, 2]], 0.0)
    high = high + np.where(high >= high.max(axis=0) - 1e-9, grow[[1, 3]], 0.0)
    return np.column_stack([(0.5 * (low + high)) @ axes, np.log(high - low), parts[:, 4] + grow[4],
                            np.full(len(parts), turn)])


def _volume(parts: np.ndarray) -> float:
    return float(np.exp(parts[:, 2:5].sum(axis=1)).sum())


def _stepped(box: BoxFit, outline: Outline, axis: int) -> tuple[ObjectProxy, np.ndarray]:
    """`box` cut across its width (`axis` 0) or depth (1) into two parts of their own heights,
    searched with the cut, place, sizes and turn for the best agreement with `outline`; with
    its parts (`silhouette`'s parameters)."""
    shown, directions = outline.cropped()
    room = outline.room()
    probe = outline.probe
    start = np.array([box.bottom[0] - probe[0], box.bottom[1] - probe[1], *np.log(box.size[:2]), box.turn, 0.0,
                      np.log(box.size[2]), np.log(box.size[2])])

    def score(params: np.ndarray) -> float:
        parts = _parts(params, axis)
        if room is not None and not all(inside_polygon(_part_footprint(p), room).all() for p in parts):
            return -1.0  # through a wall: never taken
        return agreement(np.logical_or.reduce([silhouette(p, directions, outline.camera) for p in parts]), shown)

    params, fitted = climb(score, start, score(start), _STEP_MOVES, budget=_STEP_BUDGET)
    x, y, log_w, log_d, turn, cut, low, high = params
    size = np.exp([log_w, log_d, max(low, high)])
    details = {"bottom_centre": np.round([probe[0] + x, probe[1] + y, outline.floor_z], 4).tolist(),
               "size_m": np.round(size, 4).tolist(), "turn_deg": round(float(np.degrees(turn)), 2),
               "steps_along": ("width", "depth")[axis], "step_share": round(_share(cut), 3),
               "step_heights_m": np.round(np.exp([low, high]), 4).tolist()}
    return (ObjectProxy(_step_solid(params, axis, probe, outline.floor_z), "stepped box", size, fitted,
                        int(outline.shown.sum()), details), np.array(_parts(params, axis)))


def _share(cut: float) -> float:
    return float(1.0 / (1.0 + np.exp(-cut)))


def _parts(params: np.ndarray, axis: int) -> list[np.ndarray]:
    """The two parts of a stepped box as `silhouette`'s box parameters (from the probe)."""
    x, y, log_w, log_d, turn, cut, low, high = params
    sides = np.exp([log_w, log_d])
    along = np.array([np.cos(turn), np.sin(turn)]) if axis == 0 else np.array([-np.sin(turn), np.cos(turn)])
    share = _share(cut)
    parts = []
    for start, stop, log_h in ((0.0, share, low), (share, 1.0, high)):
        centre = np.array([x, y]) + ((start + stop) / 2.0 - 0.5) * sides[axis] * along
        size = sides.copy()
        size[axis] *= stop - start
        parts.append(np.array([centre[0], centre[1], *np.log(size), log_h, turn]))
    return parts


def _part_footprint(part: np.ndarray) -> np.ndarray:
    x, y, log_w, log_d, _, turn = part
    return BoxFit(np.array([x, y, 0.0]), np.exp([log_w, log_d, 0.0]), float(turn), 0.0, 0).corners()[:4, :2]


def _step_solid(params: np.ndarray, axis: int, probe: np.ndarray, floor_z: float) -> Solid:
    """The stepped box as one solid: its side profile (the cut's two heights) swept across it."""
    x, y, log_w, log_d, turn, cut, low, high = params
    sides = np.exp([log_w, log_d])
    width_axis = np.array([np.cos(turn), np.sin(turn), 0.0])
    depth_axis = np.array([-np.sin(turn), np.cos(turn), 0.0])
    u = (width_axis, depth_axis)[axis]
    sweep = np.cross(u, (0.0, 0.0, 1.0))
    length, across = sides[axis], sides[1 - axis]
    cut_at = _share(cut) * length
    h1, h2 = np.exp([low, high])
    profile = np.array([[0.0, 0.0], [length, 0.0], [length, h2], [cut_at, h2], [cut_at, h1], [0.0, h1]])
    origin = np.array([probe[0] + x, probe[1] + y, floor_z]) - 0.5 * length * u - 0.5 * across * sweep
    return Solid(profile, origin, np.stack([u, (0.0, 0.0, 1.0), sweep]), float(across))
