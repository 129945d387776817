"""What the artist clicked: the floor's corners, an optional wall-ceiling point, the scale.

The click file (`dimred room CLICKS.json`) is a JSON object:

    {"width": 2048, "height": 1024,                    the panorama's size in pixels
     "floor": [[x, y], ...],                           3 or more floor corners, in order round the room
     "ceiling": [x, y],                                optional: a point where a wall meets the ceiling
     "camera_height": 1.6,                             metres above the floor (default 1.6) ...
     "known_length": {"kind": "wall", "edge": 0, "metres": 3.2},        ... or one known length:
                     {"kind": "vertical", "from": [x, y], "to": [x, y], "metres": 2.0}  (a door's height)
                     {"kind": "floor", "from": [x, y], "to": [x, y], "metres": 1.2}     (a rug's side)
     "manhattan": true,                                optional: walls at right angles
     "objects": [{"name": "Armchair", "click": [x, y]},                 optional: proxies of objects to remove,
                 {"name": "Table", "footprint": [[x, y], ...]}]}         from one click inside each, or from
                                                                        its contact points with the floor

Pixel coordinates are (column, row), row 0 at the top, whole numbers at pixel centres
(`projection`). A "wall" length is that of the fitted floor's edge from corner `edge` to the
next; a "vertical" one runs from a floor point straight up to the clicked top. An object's
"footprint" is 3 or more points where it meets the floor, in order round it.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

from ..errors import DimredError

Point = tuple[float, float]

DEFAULT_CAMERA_HEIGHT = 1.6
LENGTH_KINDS = ("wall", "vertical", "floor")


@dataclass(frozen=True)
class KnownLength:
    """A length in the room the scale is taken from: `kind` one of LENGTH_KINDS; `edge` for a
    wall, `start` and `end` clicks for the others."""

    kind: str
    metres: float
    edge: int = 0
    start: Point | None = None
    end: Point | None = None

    def to_dict(self) -> dict[str, Any]:
        if self.kind == "wall":
            return {"kind": "wall", "edge": self.edge, "metres": self.metres}
        return {"kind": self.kind, "from": list(self.start), "to": list(self.end), "metres": self.metres}


@dataclass(frozen=True)
class ObjectClicks:
    """An object to make a proxy of: one `click` inside it, or its `footprint`, the points where
    it meets the floor in order round it."""

    name: str
    click: Point | None = None
    footprint: tuple[Point, ...] = ()

    def points(self) -> tuple[Point, ...]:
        return self.footprint if self.click is None else (self.click,)

    def to_dict(self) -> dict[str, Any]:
        if self.click is not None:
            return {"name": self.name, "click": list(self.click)}
        return {"name": self.name, "footprint": [list(p) for p in self.footprint]}


@dataclass(frozen=True)
class RoomClicks:
    """The clicks of one room in a `width` x `height` panorama, checked on construction."""

    width: int
    height: int
    floor: tuple[Point, ...]
    ceiling: Point | None = None
    camera_height: float | None = None
    known_length: KnownLength | None = None
    manhattan: bool = False
    objects: tuple[ObjectClicks, ...] = ()

    def __post_init__(self) -> None:
        _check(self)

    @property
    def scale_source(self) -> str:
        return "camera height" if self.known_length is None else f"known {self.known_length.kind} length"

    def height_or_default(self) -> float:
        return DEFAULT_CAMERA_HEIGHT if self.camera_height is None else self.camera_height

    def click_count(self) -> int:
        """How many points were clicked: floor corners, the ceiling point, the known length's
        ends, and every object's click or contact points (a typed height or length is no click)."""
        length = self.known_length
        ends = 0 if length is None or length.kind == "wall" else 2
        return (len(self.floor) + (self.ceiling is not None) + ends
                + sum(len(obj.points()) for obj in self.objects))

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"width": self.width, "height": self.height, "floor": [list(p) for p in self.floor]}
        if self.ceiling is not None:
            out["ceiling"] = list(self.ceiling)
        if self.camera_height is not None:
            out["camera_height"] = self.camera_height
        if self.known_length is not None:
            out["known_length"] = self.known_length.to_dict()
        out["manhattan"] = self.manhattan
        if self.objects:
            out["objects"] = [obj.to_dict() for obj in self.objects]
        return out

    def to_json(self) -> str:
        return json.dumps(self.to_dict(), indent=1)


def from_dict(data: object) -> RoomClicks:
    """The clicks of a parsed click file; DimredError naming the first thing wrong."""
    if not isinstance(data, dict):
        raise DimredError("the click file must hold a JSON object with width, height and floor")
    unknown = set(data) - {"width", "height", "floor", "ceiling", "camera_height", "known_length", "manhattan",
                                "objects"}
    if unknown:
        raise DimredError(f"the click file has unknown keys {sorted(unknown)}")
    for key in ("width", "height", "floor"):
        if key not in data:
            raise DimredError(f"the click file has no '{key}'")
    floor = data["floor"]
    if not isinstance(floor, list):
        raise DimredError("'floor' must be a list of [x, y] pixel coordinates")
    return RoomClicks(
        width=_integer(data["width"], "width"), height=_integer(data["height"], "height"),
        floor=tuple(_point(p, f"floor corner {i}") for i, p in enumerate(floor)),
        ceiling=None if data.get("ceiling") is None else _point(data["ceiling"], "the ceiling point"),
        camera_height=None if data.get("camera_height") is None else _number(data["camera_height"], "camera_height"),
        known_length=None if data.get("known_length") is None else _known_length(data["known_length"]),
        manhattan=_boolean(data.get("manhattan", False)),
        objects=_objects(data.get("objects", [])),
    )


def from_json(text: str) -> RoomClicks:
    try:
        data = json.loads(text)
    except json.JSONDecodeError as error:
        raise DimredError(f"the click file is not valid JSON: {error}") from None
    return from_dict(data)


def _known_length(data: object) -> KnownLength:
    if not isinstance(data, dict) or data.get("kind") not in LENGTH_KINDS:
        raise DimredError(f"'known_length' must be an object whose kind is one of {', '.join(LENGTH_KINDS)}")
    if "metres" not in data:
        raise DimredError("'known_length' has no 'metres'")
    metres = _number(data["metres"], "the known length")
    if data["kind"] == "wall":
        return KnownLength("wall", metres, edge=_integer(data.get("edge"), "the known wall's edge"))
    for key in ("from", "to"):
        if key not in data:
            raise DimredError(f"the known {data['kind']} length has no '{key}' click")
    return KnownLength(data["kind"], metres, start=_point(data["from"], "the known length's start"),
                       end=_point(data["to"], "the known length's end"))


def _objects(data: object) -> tuple[ObjectClicks, ...]:
    if not isinstance(data, list):
        raise DimredError("'objects' must be a list of objects, each with a name and a click or a footprint")
    out = []
    for i, item in enumerate(data):
        if not isinstance(item, dict) or not isinstance(item.get("name"), str) or not item["name"]:
            raise DimredError(f"object {i} must be an object with a 'name'")
        name = item["name"]
        unknown = set(item) - {"name", "click", "footprint"}
        if unknown:
            raise DimredError(f"object '{name}' has unknown keys {sorted(unknown)}")
        if ("click" in item) == ("footprint" in item):
            raise DimredError(f"object '{name}' needs a 'click' inside it or a 'footprint', one of them")
        if "click" in item:
            out.append(ObjectClicks(name, click=_point(item["click"], f"the click in '{name}'")))
            continue
        footprint = item["footprint"]
        if not isinstance(footprint, list):
            raise DimredError(f"the footprint of '{name}' must be a list of [x, y] pixel coordinates")
        out.append(ObjectClicks(name, footprint=tuple(_point(p, f"contact point {j} of '{name}'")
                                                      for j, p in enumerate(footprint))))
    return tuple(out)


def _check(clicks: RoomClicks) -> None:
    if clicks.width < 2 or clicks.height < 1:
        raise DimredError(f"the panorama size {clicks.width} × {clicks.height} is not a panorama's")
    if len(clicks.floor) < 3:
        raise DimredError(f"a floor needs 3 or more corners, {len(clicks.floor)} clicked")
    if clicks.camera_height is not None and not clicks.camera_height > 0.0:
        raise DimredError(f"the camera height must be above 0 m, got {clicks.camera_height:g}")
    if clicks.camera_height is not None and clicks.known_length is not None:
        raise DimredError("give the camera height or a known length, not both")
    named = [(p, f"floor corner {i}") for i, p in enumerate(clicks.floor)]
    if clicks.ceiling is not None:
        named.append((clicks.ceiling, "the ceiling point"))
    length = clicks.known_length
    if length is not None:
        if not length.metres > 0.0:
            raise DimredError(f"the known length must be above 0 m, got {length.metres:g}")
        if length.kind == "wall" and not 0 <= length.edge < len(clicks.floor):
            raise DimredError(f"the known wall {length.edge} is not one of the floor's {len(clicks.floor)} edges")
        if length.kind != "wall":
            named += [(length.start, "the known length's start"), (length.end, "the known length's end")]
    for obj in clicks.objects:
        if obj.click is None and len(obj.footprint) < 3:
            raise DimredError(f"the footprint of '{obj.name}' needs 3 or more contact points, "
                              f"{len(obj.footprint)} clicked")
        named += [(p, f"the click in '{obj.name}'" if obj.click is not None else f"contact point {j} of '{obj.name}'")
                  for j, p in enumerate(obj.points())]
    for (x, y), what in named:
        if not (-0.5 <= x < clicks.width - 0.5 and -0.5 <= y <= clicks.height - 0.5):
            raise DimredError(f"{what} ({x:g}, {y:g}) lies outside the {clicks.width} × {clicks.height} panorama")


def _point(value: object, what: str) -> Point:
    if not isinstance(value, (list, tuple)) or len(value) != 2:
        raise DimredError(f"{what} must be [x, y] in pixels, got {value!r}")
    return (_number(value[0], what), _number(value[1], what))


def _number(value: object, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise DimredError(f"{what} must be a finite number, got {value!r}")
    return float(value)


def _integer(value: object, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise DimredError(f"{what} must be a whole number, got {value!r}")
    return value


def _boolean(value: object) -> bool:
    if not isinstance(value, bool):
        raise DimredError(f"'manhattan' must be true or false, got {value!r}")
    return value
