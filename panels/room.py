"""The sidebar section "Match Room": the clicks, the scale, the room's fit and its diagnostics."""
from __future__ import annotations

import json

import bpy

from ..operators.room import ROOM_DIAGNOSTICS_IMAGE
from .sidebar import CATEGORY


class DIMRED_PT_room(bpy.types.Panel):
    bl_label = "Match Room"
    bl_idname = "DIMRED_PT_room"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = CATEGORY
    bl_parent_id = "DIMRED_PT_main"

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        room = context.scene.dimred_room
        row = layout.row(align=True)
        row.operator("dimred.room_click", icon='RESTRICT_SELECT_OFF')
        row.operator("dimred.look_from_probe", text="", icon='VIEW_CAMERA')
        row.operator("dimred.room_suggest", text="", icon='LIGHT')
        row.operator("dimred.room_load_clicks", text="", icon='FILEBROWSER')
        row.operator("dimred.room_save_clicks", text="", icon='FILE_TICK')
        row.operator("dimred.room_clear", text="", icon='X')
        if room.width:
            layout.label(text=f"Clicks on a {room.width} × {room.height} panorama")
        column = layout.column(align=True)
        for index, corner in enumerate(room.corners):
            row = column.row(align=True)
            row.prop(corner, "point", text=f"Corner {index}")
            row.operator("dimred.room_remove_corner", text="", icon='REMOVE').index = index
        layout.prop(room, "manhattan")
        layout.prop(room, "scale_from")
        if room.scale_from == 'HEIGHT':
            layout.prop(room, "camera_height")
        else:
            layout.prop(room, "known_length")
            if room.scale_from == 'WALL':
                layout.prop(room, "known_wall")
            else:
                layout.prop(room, "length_start")
                layout.prop(room, "length_end")
        row = layout.row(align=True)
        row.prop(room, "use_ceiling")
        if room.use_ceiling:
            row.prop(room, "ceiling", text="")
        else:
            row.prop(room, "ceiling_height")
        row = layout.row(align=True)
        row.operator("dimred.match_room", icon='MESH_CUBE')
        row.operator("dimred.match_room", text="Snap to Photo", icon='SNAP_ON').snap = True
        row = layout.row(align=True)
        row.operator("dimred.object_from_photo", icon='CUBE')
        row.operator("dimred.object_footprint", text="", icon='MOD_SOLIDIFY')
        row.operator("dimred.fit_box", icon='FULLSCREEN_ENTER')
        if room.problem:
            layout.label(text=room.problem, icon='ERROR')
        _fit(layout, room.summary)
        image = bpy.data.images.get(ROOM_DIAGNOSTICS_IMAGE)
        if image is not None:
            image.preview_ensure()
            layout.template_icon(icon_value=image.preview.icon_id, scale=8.0)
            layout.operator("dimred.show_room_diagnostics", icon='IMAGE_DATA')


def _fit(layout: bpy.types.UILayout, stored: str) -> None:
    try:
        fit = json.loads(stored) if stored else {}
    except json.JSONDecodeError:
        return
    if not fit:
        return
    layout.label(text=(f"Camera {fit['camera_height_m']:.2f} m, ceiling {fit['ceiling_height_m']:.2f} m "
                       f"({fit['scale_from']})"), icon='CHECKMARK')
    layout.label(text=f"Corners within {max(fit['corner_error_px']):.2f} px of their clicks")


classes = (DIMRED_PT_room,)

register, unregister = bpy.utils.register_classes_factory(classes)
