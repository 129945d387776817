"""Operators that set up a removal: the probe centre, the object to remove, the target surfaces."""
from __future__ import annotations

import bpy


class DIMRED_OT_set_probe_center(bpy.types.Operator):
    bl_idname = "dimred.set_probe_center"
    bl_label = "Set Probe Centre"
    bl_description = (
        "Set the point the panorama was taken from: the active Empty's location, "
        "else the 3D cursor"
    )
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return context.scene is not None

    def execute(self, context: bpy.types.Context) -> set[str]:
        settings = context.scene.dimred
        active = context.active_object
        if active is not None and active.type == 'EMPTY':
            location, source = active.matrix_world.translation, f"Empty '{active.name}'"
        else:
            location, source = context.scene.cursor.location, "the 3D cursor"
        settings.probe_center = location
        settings.use_probe_center = True
        self.report({'INFO'}, "Probe centre set from {} ({:.3f}, {:.3f}, {:.3f})".format(source, *location))
        return {'FINISHED'}


class DIMRED_OT_mark_remove(bpy.types.Operator):
    bl_idname = "dimred.mark_remove"
    bl_label = "Mark Object to Remove"
    bl_description = "Mark the active mesh as the real object to remove from the panorama"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        active = context.active_object
        if active is None:
            cls.poll_message_set("No active object: click the mesh of the object to remove")
            return False
        if active.type != 'MESH':
            cls.poll_message_set(f"The active object '{active.name}' is not a mesh but {active.type.title()}")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        settings = context.scene.dimred
        settings.mark(context.active_object)
        # The object to remove cannot also be a surface to edit.
        for index in reversed(range(len(settings.surfaces))):
            if settings.surfaces[index].object == settings.target:
                settings.surfaces.remove(index)
        self.report({'INFO'}, f"'{settings.target.name}' will be removed")
        return {'FINISHED'}


class DIMRED_OT_mark_surface(bpy.types.Operator):
    bl_idname = "dimred.mark_surface"
    bl_label = "Toggle Target Surfaces"
    bl_description = (
        "Add the selected meshes to the surfaces the removal edits, or take them out if they are "
        "already there. Without any, the surfaces are found automatically"
    )
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if not any(obj.type == 'MESH' for obj in context.selected_objects):
            cls.poll_message_set("Select the meshes of the surfaces to edit (floor, walls)")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        settings = context.scene.dimred
        added, removed, skipped = [], [], []
        for obj in context.selected_objects:
            if obj.type != 'MESH':
                continue
            if obj == settings.target:
                skipped.append(obj.name)
                continue
            index = next((i for i, item in enumerate(settings.surfaces) if item.object == obj), None)
            if index is None:
                settings.surfaces.add().object = obj
                added.append(obj.name)
            else:
                settings.surfaces.remove(index)
                removed.append(obj.name)
        parts = [f"{label}: {', '.join(names)}" for label, names in
                 (("added", added), ("removed", removed), ("skipped (the object to remove)", skipped)) if names]
        self.report({'INFO'}, "Surfaces " + "; ".join(parts))
        return {'FINISHED'}


classes = (DIMRED_OT_set_probe_center, DIMRED_OT_mark_remove, DIMRED_OT_mark_surface)

register, unregister = bpy.utils.register_classes_factory(classes)
