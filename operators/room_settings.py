"""The clicks of Match Room, kept on the scene as `scene.dimred_room`.

Moving a click (its x or y), or changing the height, the known length or the snapping, re-fits
a room already matched: the Floor, Walls and Ceiling follow at once. A change that shows no
room leaves the room as it was and puts the reason in `problem`, which the panel shows.
"""
from __future__ import annotations

import json

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    StringProperty,
)

from ..addon.errors import DimredError

SCALE_ITEMS = (
    ('HEIGHT', "Camera Height", "The camera's height above the floor"),
    ('WALL', "Wall Length", "The length of one wall, from its corner to the next"),
    ('VERTICAL', "Vertical Length", "A vertical length standing on the floor, e.g. a door's height"),
    ('FLOOR', "Floor Length", "A length between two points on the floor"),
)
_KINDS = {'WALL': "wall", 'VERTICAL': "vertical", 'FLOOR': "floor"}


def _refit(item: bpy.types.PropertyGroup, context: bpy.types.Context) -> None:
    refit(item.id_data)


def refit(scene: bpy.types.Scene) -> None:
    """Re-fit the scene's room to its clicks if it was matched; a refusal goes to `problem`."""
    room = scene.dimred_room
    if not room.matched or room.updating:
        return
    from ..addon.blender import room_builder

    try:
        fitted = room_builder.match_room(scene, room.clicks(), ceiling_height=room.ceiling_height)
    except DimredError as error:
        room.problem = str(error)
    else:
        room.problem = ""
        room.summary = json.dumps(fitted.summary())


def _click(name: str, description: str) -> FloatVectorProperty:
    return FloatVectorProperty(name=name, description=description, size=2, precision=1, update=_refit)


class DimredRoomClick(bpy.types.PropertyGroup):
    """One floor corner clicked in the panorama: (column, row) in pixels, row 0 at the top."""

    point: _click("Corner", "Where the corner is in the panorama: column, row (pixels, row 0 at the top)")


class DimredRoom(bpy.types.PropertyGroup):
    """What Match Room fits the room to."""

    corners: CollectionProperty(type=DimredRoomClick)
    width: IntProperty(name="Width", description="Width in pixels of the panorama the clicks were made on",
                       default=0, min=0)
    height: IntProperty(name="Height", description="Height in pixels of the panorama the clicks were made on",
                        default=0, min=0)
    use_ceiling: BoolProperty(name="Ceiling Point", description="Take the ceiling's height from a clicked point "
                              "where a wall meets the ceiling", update=_refit)
    ceiling: _click("Ceiling Point", "A point where a wall meets the ceiling (pixels)")
    ceiling_height: FloatProperty(name="Ceiling Height", description="The ceiling's height where no ceiling point "
                                  "is clicked", default=2.5, unit='LENGTH', update=_refit)
    scale_from: EnumProperty(name="Scale From", items=SCALE_ITEMS, default='HEIGHT', update=_refit)
    # No hard minimum: a height <= 0 must reach the fit and be refused with a message.
    camera_height: FloatProperty(name="Camera Height", description="The camera's height above the floor",
                                 default=1.6, unit='LENGTH', update=_refit)
    known_length: FloatProperty(name="Length", description="The known length", default=2.0, unit='LENGTH',
                                update=_refit)
    known_wall: IntProperty(name="Wall", description="The wall of known length: from this corner to the next",
                            default=0, min=0, update=_refit)
    length_start: _click("Start", "The known length's start (on the floor), in pixels")
    length_end: _click("End", "The known length's end, in pixels")
    manhattan: BoolProperty(name="Right Angles", description="Snap the walls to right angles (a Manhattan room)",
                            update=_refit)
    matched: BoolProperty(options={'HIDDEN'})
    updating: BoolProperty(options={'HIDDEN'})
    problem: StringProperty(options={'HIDDEN'})
    summary: StringProperty(options={'HIDDEN'})

    def clicks(self):
        """The clicks as the engine takes them; DimredError when they are not complete."""
        from ..addon.roommatch.clicks import KnownLength, RoomClicks

        if self.width <= 0 or self.height <= 0:
            raise DimredError("no panorama size for the clicks: click in the panorama or load a click file")
        length = None
        if self.scale_from == 'WALL':
            length = KnownLength("wall", self.known_length, edge=self.known_wall)
        elif self.scale_from != 'HEIGHT':
            length = KnownLength(_KINDS[self.scale_from], self.known_length, start=tuple(self.length_start),
                                 end=tuple(self.length_end))
        return RoomClicks(self.width, self.height, tuple(tuple(c.point) for c in self.corners),
                          ceiling=tuple(self.ceiling) if self.use_ceiling else None,
                          camera_height=self.camera_height if length is None else None,
                          known_length=length, manhattan=self.manhattan)

    def load(self, clicks) -> None:
        """Take over a click file's clicks (without re-fitting on every value)."""
        self.updating = True
        try:
            self.width, self.height = clicks.width, clicks.height
            self.corners.clear()
            for point in clicks.floor:
                self.corners.add().point = point
            self.use_ceiling = clicks.ceiling is not None
            if clicks.ceiling is not None:
                self.ceiling = clicks.ceiling
            self.manhattan = clicks.manhattan
            length = clicks.known_length
            if length is None:
                self.scale_from = 'HEIGHT'
                self.camera_height = clicks.height_or_default()
            else:
                self.scale_from = next(k for k, v in _KINDS.items() if v == length.kind)
                self.known_length = length.metres
                self.known_wall = length.edge
                if length.start is not None:
                    self.length_start, self.length_end = length.start, length.end
        finally:
            self.updating = False


classes = (DimredRoomClick, DimredRoom)


def register() -> None:
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.dimred_room = bpy.props.PointerProperty(type=DimredRoom)


def unregister() -> None:
    del bpy.types.Scene.dimred_room
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
