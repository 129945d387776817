"""Sidebar panels: the removal and relocation set-up and buttons, and a summary of the last run's report."""
from __future__ import annotations

import json

import bpy

from ..operators.settings import OVERRIDABLE
from ..operators.support import session, world_layer

CATEGORY = "Diminished Reality"


class DIMRED_PT_main(bpy.types.Panel):
    bl_label = "Diminished Reality"
    bl_idname = "DIMRED_PT_main"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = CATEGORY

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        settings = context.scene.dimred

        box = layout.box()
        box.label(text="Probe Centre", icon='WORLD')
        box.prop(settings, "use_probe_center", text="Use This Point")
        column = box.column(align=True)
        column.enabled = settings.use_probe_center
        column.prop(settings, "probe_center", text="")
        box.operator("dimred.set_probe_center", icon='PIVOT_CURSOR')

        box = layout.box()
        box.label(text="Object to Remove", icon='OBJECT_DATA')
        box.prop(settings, "target", text="")
        row = box.row(align=True)
        row.operator("dimred.mark_remove", icon='RESTRICT_SELECT_OFF')
        row.operator("dimred.align", icon='SNAP_ON')
        box.prop(settings, "align_first")
        box.prop(settings, "fit_height")
        box.label(text="Mask", icon='MOD_MASK')
        box.template_ID(settings, "mask_image", new="dimred.new_mask", open="image.open")

        box = layout.box()
        box.label(text="Target Surfaces", icon='MESH_PLANE')
        names = settings.surface_names()
        if names:
            column = box.column(align=True)
            for name in names:
                column.label(text=name, icon='DOT')
        else:
            box.label(text="Automatic")
        box.operator("dimred.mark_surface", icon='CHECKBOX_HLT')

        layout.prop(settings, "quality")
        layout.prop(settings, "storage")
        row = layout.row()
        row.enabled = settings.storage == 'FILE'
        row.prop(settings, "output_dir")

        running = session.active()
        column = layout.column(align=True)
        column.scale_y = 1.4
        if running is None:
            row = column.row(align=True)
            row.operator("dimred.remove", icon='TRASH')
            row.operator("dimred.relocate", text="Relocate...", icon='ORIENTATION_GIMBAL')
            # The move by the values typed here, without the interactive tool.
            row = layout.row(align=True)
            row.prop(settings, "yaw", text="Yaw °")
            row.prop(settings, "distance_scale", text="Distance ×")
            apply = row.operator("dimred.relocate", text="", icon='CHECKMARK')
            apply.yaw, apply.distance_scale = settings.yaw, settings.distance_scale
            row.operator("dimred.relocate", text="", icon='OBJECT_ORIGIN').from_transform = True
        else:
            row = column.row(align=True)
            row.progress(factor=running.fraction, type='BAR',
                         text=f"{running.stage.replace('_', ' ').capitalize()} {100 * running.fraction:.0f} %")
            row.operator("dimred.cancel", text="", icon='CANCEL')
        row = layout.row(align=True)
        row.operator("dimred.clear", icon='X')
        row.operator("dimred.save_hdri", icon='FILE_IMAGE')
        if len(settings.removals):
            column = layout.column(align=True)
            column.label(text="Removed or relocated, in order:")
            for entry in settings.removals:
                if entry.kind == 'RELOCATE':
                    column.label(text=(f"{entry.object_name}: yaw {entry.yaw:.1f}°, "
                                       f"distance ×{entry.distance_scale:.2f}"),
                                 icon='ORIENTATION_GIMBAL')
                else:
                    column.label(text=entry.object_name, icon='GHOST_ENABLED')
        box = layout.box()
        _photo_fit(box, settings.photo_fit)
        box.operator("dimred.show_diagnostics", icon='IMAGE_DATA')


class DIMRED_PT_parameters(bpy.types.Panel):
    bl_label = "Parameters"
    bl_idname = "DIMRED_PT_parameters"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = CATEGORY
    bl_parent_id = "DIMRED_PT_main"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        settings = context.scene.dimred
        layout.prop(settings, "override_parameters")
        column = layout.column(align=True)
        column.enabled = settings.override_parameters
        for name in OVERRIDABLE:
            column.prop(settings, name)


class DIMRED_PT_last_run(bpy.types.Panel):
    bl_label = "Last Run"
    bl_idname = "DIMRED_PT_last_run"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = CATEGORY
    bl_parent_id = "DIMRED_PT_main"
    bl_options = {'DEFAULT_CLOSED'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return bool(context.scene.dimred.last_report)

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        try:
            report = json.loads(context.scene.dimred.last_report)
        except json.JSONDecodeError:
            layout.label(text="The stored report is not valid JSON", icon='ERROR')
            return
        if not world_layer.has_layer(context.scene.world):
            layout.label(text="Cleared: the world shows the original", icon='INFO')

        seconds = report.get("seconds", {})
        column = layout.column(align=True)
        for stage, value in seconds.items():
            if isinstance(value, (int, float)):
                column.label(text=f"{stage}: {value:.2f} s")
        for line in _lines(report.get("skipped")):
            layout.label(text=f"Skipped {line}", icon='FORWARD')
        for line in _lines(report.get("warnings")):
            layout.label(text=line, icon='ERROR')
        for line in _lines(report.get("guards")):
            layout.label(text=line, icon='INFO')
        if isinstance(report.get("relocation"), dict):
            layout.label(text=f"Moved: {session.move_summary(report['relocation'])}", icon='ORIENTATION_GIMBAL')


def _photo_fit(layout: bpy.types.UILayout, stored: str) -> None:
    """A line on how the proxy fitted the photograph (the share of its silhouette and the
    photographed object's that agree) and one on the alignment's correction."""
    try:
        fit = json.loads(stored) if stored else {}
    except json.JSONDecodeError:
        return
    segmentation, alignment = fit.get("segmentation"), fit.get("alignment")
    if isinstance(segmentation, dict) and "agreement" in segmentation:
        layout.label(text=f"{fit.get('object', '')}: {100 * segmentation['agreement']:.0f} % of the outline agrees",
                     icon='SHADING_BBOX')
    if isinstance(alignment, dict) and alignment.get("applied"):
        shift = sum(v * v for v in alignment["shift_cm"]) ** 0.5
        layout.label(text=(f"Aligned: {shift:.1f} cm, {alignment['turn_deg']:+.1f}°, "
                           f"{alignment['scale_percent']:+.1f} %"), icon='SNAP_ON')
    elif isinstance(alignment, dict):
        layout.label(text="Not aligned: the proxy stays where it was", icon='ERROR')


def _lines(entries: object) -> list[str]:
    """Report entries, a dict (name -> detail) or a list, as one line each."""
    if isinstance(entries, dict):
        return [f"{name}: {_text(detail)}" for name, detail in entries.items()]
    if isinstance(entries, list):
        return [_text(item) for item in entries]
    return []


def _text(value: object) -> str:
    if isinstance(value, dict) and {"stage", "reason"} <= value.keys():
        return f"{value['stage']}: {value['reason']}"
    if isinstance(value, dict):
        return ", ".join(f"{k}: {v}" for k, v in value.items())
    return str(value)


classes = (DIMRED_PT_main, DIMRED_PT_parameters, DIMRED_PT_last_run)

register, unregister = bpy.utils.register_classes_factory(classes)
