"""Match Room: click the room's floor corners in the panorama, then build Floor, Walls and Ceiling.

`dimred.room_click` adds clicks: interactively in an Image Editor showing the panorama, or in a
3D viewport showing the world (`dimred.look_from_probe`: through a camera at the probe centre) (left
click a floor corner, Ctrl+click the wall-ceiling point, Shift+click the known length's ends,
Alt+click to move the nearest corner, Enter or right click to match, Esc to stop), or from a
script with `kind`, `x` and `y`.
`dimred.match_room` fits the room to the clicks (`addon.roommatch`), builds it, sets the probe
centre and draws the room diagnostics picture. Click files (`dimred room`'s JSON) load and save.
`dimred.object_from_photo` (one click inside an object) and `dimred.object_footprint` (its
contact points with the floor) build the proxy of an object to remove and mark it.
"""
from __future__ import annotations

import json

import bpy
import numpy as np
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
from . import room_settings
from .support import pictures

ROOM_DIAGNOSTICS_IMAGE = "Dimred Room Diagnostics"

KIND_ITEMS = (
    ('FLOOR', "Floor Corner", "A corner of the floor, in order round the room"),
    ('CEILING', "Ceiling Point", "A point where a wall meets the ceiling"),
    ('LENGTH_START', "Length Start", "The known length's start (on the floor)"),
    ('LENGTH_END', "Length End", "The known length's end"),
    ('MOVE', "Move Corner", "The nearest floor corner moves here (a matched room re-fits)"),
)


def add_click(scene: bpy.types.Scene, kind: str, x: float, y: float) -> str:
    """Record one click; the message says what it was."""
    room = scene.dimred_room
    if kind == 'FLOOR':
        room.corners.add().point = (x, y)
        return f"floor corner {len(room.corners) - 1} at ({x:.1f}, {y:.1f})"
    if kind == 'MOVE':
        if not room.corners:
            raise DimredError("there is no floor corner to move yet")
        points = np.array([tuple(c.point) for c in room.corners])
        gap = np.abs(points - (x, y))
        gap[:, 0] = np.minimum(gap[:, 0], room.width - gap[:, 0])  # the short way round the seam
        index = int(np.argmin(np.hypot(gap[:, 0], gap[:, 1])))
        room.corners[index].point = (x, y)
        return f"floor corner {index} moved to ({x:.1f}, {y:.1f})"
    if kind == 'CEILING':
        room.ceiling, room.use_ceiling = (x, y), True
        return f"ceiling point at ({x:.1f}, {y:.1f})"
    if kind == 'LENGTH_START':
        room.length_start = (x, y)
    else:
        room.length_end = (x, y)
    return f"known length's {'start' if kind == 'LENGTH_START' else 'end'} at ({x:.1f}, {y:.1f})"


def match(scene: bpy.types.Scene, *, snap: bool = False) -> str:
    """Fit and build the room from the scene's clicks (with `snap`, first moved onto the
    photograph's wall-floor edges); the summary line. DimredError: nothing changed."""
    from ..addon.blender import reader, room_builder
    from ..addon.roommatch.diagnostics import room_picture
    from ..addon.roommatch.fit import fit_room
    from ..addon.roommatch.refine import refine_clicks

    room = scene.dimred_room
    clicks = room.clicks()
    rotation = room_builder.panorama_rotation(scene)
    try:
        panorama = reader.panorama_pixels(scene)
    except DimredError:
        if snap:
            raise
        panorama = None  # no panorama in the world: the room stands, there is nothing to draw it over
    snapped = ""
    if snap:
        first = fit_room(clicks, rotation=rotation, ceiling_height=room.ceiling_height)
        clicks, shown = refine_clicks(panorama, clicks, first, rotation=rotation)
        snapped = f", {int(shown.sum())} of {len(shown)} walls snapped to the photograph"
    fitted = room_builder.match_room(scene, clicks, ceiling_height=room.ceiling_height)
    if snap:
        room.load(clicks)
    room.matched, room.problem = True, ""
    room.summary = json.dumps(fitted.summary())
    if panorama is not None:
        show_room_picture(room_picture(panorama, fitted, clicks, rotation=rotation))
    return (f"Room matched: {len(clicks.floor)} corners, camera {fitted.camera_height:.2f} m "
            f"({fitted.scale_source}), ceiling {fitted.ceiling_height:.2f} m, "
            f"corners within {fitted.corner_errors.max():.2f} px of their clicks{snapped}")


def show_room_picture(picture: np.ndarray) -> None:
    pictures.show_diagnostics(pictures.Picture.of(picture), ROOM_DIAGNOSTICS_IMAGE)


class DIMRED_OT_match_room(bpy.types.Operator):
    bl_idname = "dimred.match_room"
    bl_label = "Match Room"
    bl_description = ("Build Floor, Walls and Ceiling from the clicked floor corners and the camera height (or a "
                      "known length), and set the probe centre where the camera was")
    bl_options = {'REGISTER', 'UNDO'}

    snap: BoolProperty(name="Snap to Photo", description=(
        "First move the floor corners onto the wall-floor edges the photograph shows near them (each wall's "
        "foot fitted along its whole length); walls the photograph hides keep their clicks"))

    def execute(self, context: bpy.types.Context) -> set[str]:
        try:
            message = match(context.scene, snap=self.snap)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        self.report({'INFO'}, message)
        return {'FINISHED'}


class PanoramaClick:
    """A click's place in the panorama, for scripts (x, y on a width x height panorama) or taken
    from the mouse in the Image Editor showing it or in a 3D viewport showing the world."""

    x: FloatProperty(name="Column", description="Pixels from the left, pixel centres at whole numbers")
    y: FloatProperty(name="Row", description="Pixels from the top, pixel centres at whole numbers")
    width: IntProperty(name="Width", description="The panorama's width the click was made on (0: the world's)", min=0)
    height: IntProperty(name="Height", description="The panorama's height the click was made on (0: the world's)",
                        min=0)

    def size(self, scene: bpy.types.Scene) -> tuple[int, int]:
        size = (self.width, self.height) if self.width and self.height else _world_size(scene)
        if size is None:
            raise DimredError("give the panorama's width and height: the world shows no panorama")
        return size

    def take_mouse(self, context: bpy.types.Context, event: bpy.types.Event) -> None:
        mouse = (event.mouse_region_x, event.mouse_region_y)
        if context.area.type == 'VIEW_3D':
            # The viewport shows the world behind everything along the view ray: its direction
            # is the panorama's pixel, wherever the view stands.
            from bpy_extras import view3d_utils

            from ..addon.blender import room_builder

            direction = view3d_utils.region_2d_to_vector_3d(context.region, context.region_data, mouse)
            self.x, self.y, self.width, self.height = room_builder.panorama_pixel(context.scene, direction)
            return
        image = context.space_data.image
        u, v = context.region.view2d.region_to_view(*mouse)
        self.width, self.height = image.size
        self.x, self.y = u * self.width - 0.5, (1.0 - v) * self.height - 0.5


class DIMRED_OT_room_click(PanoramaClick, bpy.types.Operator):
    bl_idname = "dimred.room_click"
    bl_label = "Click Room"
    bl_description = ("Click the floor's corners in order round the room in the Image Editor showing the panorama "
                      "or in the 3D viewport looking from the probe "
                      "(Ctrl: the wall-ceiling point, Shift: the known length's ends, Alt: move the nearest corner "
                      "here); Enter or right click matches the room, Esc stops")
    bl_options = {'REGISTER', 'UNDO'}

    kind: EnumProperty(name="Kind", items=KIND_ITEMS, default='FLOOR')

    def execute(self, context: bpy.types.Context) -> set[str]:
        room = context.scene.dimred_room
        try:
            size = self.size(context.scene)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        if room.corners and (room.width, room.height) != size:
            self.report({'ERROR'}, f"the clicks so far were made on a {room.width} × {room.height} panorama, not "
                                   f"{size[0]} × {size[1]}: clear them first")
            return {'CANCELLED'}
        room.updating = True
        room.width, room.height = size
        room.updating = False
        try:
            self.report({'INFO'}, add_click(context.scene, self.kind, self.x, self.y).capitalize())
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        if room.problem:
            self.report({'WARNING'}, room.problem)
        return {'FINISHED'}

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if not _in_panorama_view(context):
            self.report({'ERROR'}, f"start Click Room {_WHERE}")
            return {'CANCELLED'}
        context.window_manager.modal_handler_add(self)
        context.workspace.status_text_set("Click Room: click floor corners in order; Ctrl: ceiling point; "
                                          "Shift: known length's ends; Alt: move the nearest corner; "
                                          "Enter/right click: match; Esc: stop")
        return {'RUNNING_MODAL'}

    def modal(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if event.type in {'ESC'} and event.value == 'PRESS':
            context.workspace.status_text_set(None)
            return {'CANCELLED'}
        if event.type in {'RET', 'NUMPAD_ENTER', 'RIGHTMOUSE'} and event.value == 'PRESS':
            context.workspace.status_text_set(None)
            bpy.ops.dimred.match_room()
            return {'FINISHED'}
        if event.type == 'LEFTMOUSE' and event.value == 'PRESS':
            self.take_mouse(context, event)
            room = context.scene.dimred_room
            shift_kind = 'LENGTH_END' if tuple(room.length_start) != (0.0, 0.0) else 'LENGTH_START'
            self.kind = 'MOVE' if event.alt else 'CEILING' if event.ctrl else shift_kind if event.shift else 'FLOOR'
            self.execute(context)
            context.area.tag_redraw()
            return {'RUNNING_MODAL'}
        return {'PASS_THROUGH'}


class DIMRED_OT_room_suggest(bpy.types.Operator):
    bl_idname = "dimred.room_suggest"
    bl_label = "Suggest Room"
    bl_description = ("Propose the floor's corners from the photograph's lines (a room with right-angled walls): "
                      "they replace the clicks, to accept with Match Room or correct first")
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context: bpy.types.Context) -> set[str]:
        from ..addon.blender import reader, room_builder
        from ..addon.roommatch.suggest import suggest_room

        scene = context.scene
        try:
            panorama = reader.panorama_pixels(scene)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        height, width = panorama.shape[:2]
        found = suggest_room(panorama, width=width, height=height, rotation=room_builder.panorama_rotation(scene))
        if found.clicks is None:
            self.report({'WARNING'}, found.message)
            return {'CANCELLED'}
        room = scene.dimred_room
        camera = room.camera_height
        room.load(found.clicks)
        # The suggestion has no scale: the height set stays. Nothing is built until Match Room.
        room.updating = True
        room.camera_height, room.matched = camera, False
        room.updating = False
        self.report({'INFO'}, found.message + ": check them, then Match Room")
        return {'FINISHED'}


class DIMRED_OT_object_from_photo(PanoramaClick, bpy.types.Operator):
    bl_idname = "dimred.object_from_photo"
    bl_label = "Object from Photo"
    bl_description = ("Click inside an object standing on the floor in the Image Editor showing the panorama (or "
                      "the 3D viewport looking from the probe): a box "
                      "proxy is fitted to its outline (place, width, depth, height, turn; stepped in two heights "
                      "where one part stands higher, an armchair's back; carved to the outline where no box "
                      "fits it, curved arms) and marked for removal")
    bl_options = {'REGISTER', 'UNDO'}

    name: StringProperty(name="Name", description="The new proxy's name", default="Object")

    def execute(self, context: bpy.types.Context) -> set[str]:
        from ..addon.roommatch.clicks import ObjectClicks

        return add_object(self, context, ObjectClicks(self.name, click=(self.x, self.y)))

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if not _in_panorama_view(context):
            self.report({'ERROR'}, f"click the object {_WHERE}")
            return {'CANCELLED'}
        self.take_mouse(context, event)
        return self.execute(context)


class DimredContactPoint(bpy.types.PropertyGroup):
    """One point where an object meets the floor, clicked in the panorama: (column, row) in pixels."""

    point: FloatVectorProperty(name="Point", size=2, description="Column, row in pixels, row 0 at the top")


class DIMRED_OT_object_footprint(PanoramaClick, bpy.types.Operator):
    bl_idname = "dimred.object_footprint"
    bl_label = "Object from Footprint"
    bl_description = ("Click where an object meets the floor, in order round it, in the Image Editor showing the "
                      "panorama (or the 3D viewport looking from the probe); Enter or right click: a prism over "
                      "those points, its height fitted to the object's outline, is marked for removal; Esc stops")
    bl_options = {'REGISTER', 'UNDO'}

    name: StringProperty(name="Name", description="The new proxy's name", default="Object")
    points: CollectionProperty(type=DimredContactPoint, name="Contact Points",
                               description="Where the object meets the floor (pixels), in order round it")

    def execute(self, context: bpy.types.Context) -> set[str]:
        from ..addon.roommatch.clicks import ObjectClicks

        footprint = tuple(tuple(p.point) for p in self.points)
        return add_object(self, context, ObjectClicks(self.name, footprint=footprint))

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if not _in_panorama_view(context):
            self.report({'ERROR'}, f"click the object's feet {_WHERE}")
            return {'CANCELLED'}
        self.points.clear()
        context.window_manager.modal_handler_add(self)
        context.workspace.status_text_set("Object from Footprint: click where the object meets the floor, in "
                                          "order round it; Enter/right click: fit; Esc: stop")
        return {'RUNNING_MODAL'}

    def modal(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if event.type == 'ESC' and event.value == 'PRESS':
            context.workspace.status_text_set(None)
            return {'CANCELLED'}
        if event.type in {'RET', 'NUMPAD_ENTER', 'RIGHTMOUSE'} and event.value == 'PRESS':
            context.workspace.status_text_set(None)
            return self.execute(context)
        if event.type == 'LEFTMOUSE' and event.value == 'PRESS':
            self.take_mouse(context, event)
            self.points.add().point = (self.x, self.y)
            self.report({'INFO'}, f"Contact point {len(self.points) - 1} at ({self.x:.1f}, {self.y:.1f})")
            return {'RUNNING_MODAL'}
        return {'PASS_THROUGH'}


def add_object(operator: PanoramaClick, context: bpy.types.Context, item) -> set[str]:
    """Fit the proxy of the object `item` (a click file's object) to the photograph, build it,
    mark it for removal and draw it into the room's picture; the operator's result."""
    from ..addon.blender import reader, room_builder
    from ..addon.roommatch.object_shapes import object_proxy

    scene = context.scene
    try:
        size = operator.size(scene)
        panorama, probe = reader.panorama_pixels(scene), reader.probe_center(scene)
        rotation = room_builder.panorama_rotation(scene)
        proxy = object_proxy(panorama, item, click_size=size, probe=probe, floor_z=room_builder.floor_height(scene),
                             rotation=rotation, inside=room_builder.floor_polygon(scene))
    except DimredError as error:
        operator.report({'ERROR'}, str(error))
        return {'CANCELLED'}
    obj = room_builder.proxy_object(scene, proxy.solid.mesh(item.name))
    scene.dimred.mark(obj)
    room = scene.dimred_room
    if room.matched and not room.problem:  # the room's picture shows the new proxy too
        from ..addon.roommatch.diagnostics import room_picture
        from ..addon.roommatch.fit import fit_room

        clicks = room.clicks()
        fitted = fit_room(clicks, rotation=rotation, origin=tuple(probe[:2]), ceiling_height=room.ceiling_height)
        show_room_picture(room_picture(panorama, fitted, clicks, solids=(proxy.solid,), rotation=rotation))
    width, depth, tall = proxy.size
    operator.report({'INFO'}, f"'{obj.name}': {proxy.kind} {width:.2f} × {depth:.2f} × {tall:.2f} m, "
                              f"{100 * proxy.agreement:.0f} % of the outline agrees")
    return {'FINISHED'}


def _in_panorama_view(context: bpy.types.Context) -> bool:
    """Whether the mouse is over the panorama: an Image Editor showing it, or a 3D viewport (the
    world behind the scene; Look from Probe shows it from the probe centre)."""
    area = context.area
    if area is None:
        return False
    if area.type == 'VIEW_3D':
        return context.region_data is not None
    return area.type == 'IMAGE_EDITOR' and context.space_data.image is not None


_WHERE = "in an Image Editor showing the panorama or in a 3D viewport (Look from Probe)"


class DIMRED_OT_fit_box(bpy.types.Operator):
    bl_idname = "dimred.fit_box"
    bl_label = "Fit Box to Photo"
    bl_description = ("Refit the marked box proxy to the object's outline in the panorama: its place, turn and each "
                      "of its width, depth and height (Align to Photo keeps its proportions)")
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        target = context.scene.dimred.target
        if target is None or target.type != 'MESH':
            cls.poll_message_set("Mark the box proxy to remove first")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        from ..addon.blender import reader, room_builder
        from ..addon.roommatch.object_box import refit_box

        scene = context.scene
        obj = scene.dimred.target
        corners = np.array([tuple(obj.matrix_world @ v.co) for v in obj.data.vertices])
        try:
            box = refit_box(reader.panorama_pixels(scene), corners, probe=reader.probe_center(scene),
                            floor_z=room_builder.floor_height(scene),
                            rotation=room_builder.panorama_rotation(scene), inside=room_builder.floor_polygon(scene))
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        room_builder.reshape_box(obj, box.corners())
        scene.dimred.mark(obj)
        self.report({'INFO'}, _box_line(obj.name, box))
        return {'FINISHED'}


class DIMRED_OT_room_remove_corner(bpy.types.Operator):
    bl_idname = "dimred.room_remove_corner"
    bl_label = "Remove Corner"
    bl_description = "Remove a clicked floor corner (the last one by default)"
    bl_options = {'REGISTER', 'UNDO'}

    index: IntProperty(name="Corner", default=-1)

    def execute(self, context: bpy.types.Context) -> set[str]:
        corners = context.scene.dimred_room.corners
        index = self.index if self.index >= 0 else len(corners) - 1
        if not 0 <= index < len(corners):
            self.report({'ERROR'}, f"there is no floor corner {self.index}")
            return {'CANCELLED'}
        corners.remove(index)
        room_settings.refit(context.scene)
        return {'FINISHED'}


class DIMRED_OT_room_clear(bpy.types.Operator):
    bl_idname = "dimred.room_clear"
    bl_label = "Clear Clicks"
    bl_description = "Forget the room's clicks (the room's meshes stay)"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context: bpy.types.Context) -> set[str]:
        room = context.scene.dimred_room
        room.updating = True
        room.corners.clear()
        room.use_ceiling = room.matched = False
        room.width = room.height = 0
        room.length_start = room.length_end = (0.0, 0.0)
        room.problem = room.summary = ""
        room.updating = False
        return {'FINISHED'}


class DIMRED_OT_room_load_clicks(bpy.types.Operator):
    bl_idname = "dimred.room_load_clicks"
    bl_label = "Load Clicks"
    bl_description = "Load a click file (JSON, as `dimred room` takes it), or the clicks the scene's room was made from"
    bl_options = {'REGISTER', 'UNDO'}

    filepath: StringProperty(name="File Path", subtype='FILE_PATH')

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}

    def execute(self, context: bpy.types.Context) -> set[str]:
        from ..addon.blender import room_builder
        from ..addon.roommatch import clicks as click_file

        try:
            if self.filepath:
                try:
                    with open(bpy.path.abspath(self.filepath), encoding="utf-8") as handle:
                        clicks = click_file.from_json(handle.read())
                except OSError as error:
                    raise DimredError(f"cannot read the click file: {error.strerror}: {self.filepath}") from None
            else:
                clicks = room_builder.stored_clicks(context.scene)
                if clicks is None:
                    raise DimredError("the scene keeps no clicks of a matched room: give a click file")
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        context.scene.dimred_room.load(clicks)
        self.report({'INFO'}, f"Loaded {len(clicks.floor)} floor corners")
        return {'FINISHED'}


class DIMRED_OT_room_save_clicks(bpy.types.Operator):
    bl_idname = "dimred.room_save_clicks"
    bl_label = "Save Clicks"
    bl_description = "Save the clicks as a click file (JSON), for `dimred room` or another scene"

    filepath: StringProperty(name="File Path", subtype='FILE_PATH')

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if not self.filepath:
            self.filepath = "room_clicks.json"
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}

    def execute(self, context: bpy.types.Context) -> set[str]:
        try:
            text = context.scene.dimred_room.clicks().to_json()
            path = bpy.path.ensure_ext(bpy.path.abspath(self.filepath), ".json")
            with open(path, "w", encoding="utf-8") as handle:
                handle.write(text)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        except OSError as error:
            self.report({'ERROR'}, f"cannot write the click file: {error.strerror}: {self.filepath}")
            return {'CANCELLED'}
        self.report({'INFO'}, f"Saved the clicks to {path}")
        return {'FINISHED'}


class DIMRED_OT_look_from_probe(bpy.types.Operator):
    bl_idname = "dimred.look_from_probe"
    bl_label = "Look from Probe"
    bl_description = ("Look at the panorama from the probe centre in the 3D viewport: the camera 'Probe Camera' "
                      "there, the world shown behind the room's meshes (drawn as wires); Click Room, Object from "
                      "Photo and Object from Footprint then take their clicks in the viewport")
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context: bpy.types.Context) -> set[str]:
        from ..addon.blender import room_builder
        from ..addon.roommatch.meshes import NAMES

        scene = context.scene
        camera = room_builder.probe_camera(scene)
        for name in NAMES:
            obj = scene.objects.get(name)
            if obj is not None:
                obj.display_type = 'WIRE'
        views = [area for area in (context.screen.areas if context.screen else ()) if area.type == 'VIEW_3D']
        if context.area is not None and context.area.type == 'VIEW_3D':
            views = [context.area]
        for area in views[:1]:
            space = area.spaces.active
            space.region_3d.view_perspective = 'CAMERA'
            space.shading.type = 'MATERIAL'
            space.shading.use_scene_world = True
            space.lock_camera = True  # turning the view turns the camera
        where = "in the 3D viewport" if views else "(no 3D viewport open: look through it there)"
        self.report({'INFO'}, f"Looking through '{camera.name}' at the probe centre {where}")
        return {'FINISHED'}


class DIMRED_OT_show_room_diagnostics(bpy.types.Operator):
    bl_idname = "dimred.show_room_diagnostics"
    bl_label = "Show Room Diagnostics"
    bl_description = "Show the panorama with every edge of the matched room drawn over it in an Image Editor"

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return ROOM_DIAGNOSTICS_IMAGE in bpy.data.images

    def execute(self, context: bpy.types.Context) -> set[str]:
        if not pictures.show_in_editor(context, bpy.data.images[ROOM_DIAGNOSTICS_IMAGE]):
            self.report({'WARNING'}, "no window to show the picture in")
            return {'CANCELLED'}
        return {'FINISHED'}


def _box_line(name: str, box) -> str:
    width, depth, tall = box.size
    return (f"'{name}': {width:.2f} × {depth:.2f} × {tall:.2f} m, turned {np.degrees(box.turn):.1f}°, "
            f"{100 * box.agreement:.0f} % of the outline agrees")


def _world_size(scene: bpy.types.Scene) -> tuple[int, int] | None:
    from ..addon.blender import reader

    try:
        return reader.panorama_size(scene)
    except DimredError:
        return None


classes = (DimredContactPoint, DIMRED_OT_match_room, DIMRED_OT_room_click, DIMRED_OT_room_suggest,
           DIMRED_OT_object_from_photo, DIMRED_OT_object_footprint,
           DIMRED_OT_fit_box, DIMRED_OT_room_remove_corner, DIMRED_OT_room_clear, DIMRED_OT_room_load_clicks,
           DIMRED_OT_room_save_clicks, DIMRED_OT_look_from_probe, DIMRED_OT_show_room_diagnostics)

register, unregister = bpy.utils.register_classes_factory(classes)
