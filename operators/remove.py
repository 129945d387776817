"""Operators that run the removal and manage its result: remove, cancel, clear, save HDRI.

Remove invoked from the UI computes in a worker thread (`session.RemovalSession`) while a modal
operator polls it on a timer, shows progress in the panel and the status bar, and previews the
result in the world as it refines; Esc or the panel's Cancel stops it and leaves the scene as it
was. Called from a script or in background mode (`blender -b`), the same operator runs to the
end synchronously. The engine is imported only when a run starts, so registering costs nothing.
"""
from __future__ import annotations

import bpy
from bpy.props import BoolProperty, StringProperty

from ..addon.errors import DimredError
from .run_operator import RunOperator, world_poll
from .support import session, world_layer


class DIMRED_OT_remove(RunOperator, bpy.types.Operator):
    bl_idname = "dimred.remove"
    bl_label = "Remove Object"
    bl_description = (
        "Compute the difference image that removes the marked object, its shadow and its reflected "
        "light from the panorama, and show HDRI + difference in the world. Runs in the background "
        "with progress; Esc cancels"
    )
    bl_options = {'REGISTER', 'UNDO'}


class DIMRED_OT_cancel(bpy.types.Operator):
    bl_idname = "dimred.cancel"
    bl_label = "Cancel Removal"
    bl_description = "Stop the running removal; the world stays as it was before it started"
    bl_options = {'INTERNAL'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if session.active() is None:
            cls.poll_message_set("No removal is running")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        # The modal operator sees the request at its next poll and rolls back there.
        session.active().worker.cancel()
        return {'FINISHED'}


class DIMRED_OT_clear(bpy.types.Operator):
    bl_idname = "dimred.clear"
    bl_label = "Clear Removal"
    bl_description = (
        "Remove the difference layer from the world and show the original panorama again; relocated "
        "objects go back to where the panorama shows them"
    )
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if not world_poll(cls, context):
            return False
        if session.active() is not None:
            cls.poll_message_set("A removal is running: cancel it first")
            return False
        if not world_layer.has_layer(context.scene.world) and not len(context.scene.dimred.removals):
            cls.poll_message_set("The world shows no removal")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        settings = context.scene.dimred
        for entry in settings.removals:
            obj = context.scene.objects.get(entry.object_name)
            if entry.kind == 'RELOCATE' and obj is not None:
                obj.matrix_world = entry.photographed_matrix()
        images = [world_layer.remove_layer(context.scene.world)] + [r.image for r in settings.removals]
        settings.removals.clear()
        for image in images:
            if image is not None and image.name in bpy.data.images and image.users == 0:
                bpy.data.images.remove(image)
        self.report({'INFO'}, "Removal cleared: the world shows the original panorama")
        return {'FINISHED'}


class DIMRED_OT_save_hdri(bpy.types.Operator):
    bl_idname = "dimred.save_hdri"
    bl_label = "Save Edited HDRI"
    bl_description = "Write the original panorama plus the difference to an OpenEXR file"
    bl_options = {'REGISTER'}

    filepath: StringProperty(name="File Path", subtype='FILE_PATH')
    filter_glob: StringProperty(default="*.exr", options={'HIDDEN'})
    check_existing: BoolProperty(default=True, options={'HIDDEN'})

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if not world_poll(cls, context):
            return False
        if session.active() is not None:
            cls.poll_message_set("A removal is running: wait for it to finish")
            return False
        if world_layer.layer_image(context.scene.world) is None:
            cls.poll_message_set("Run Remove first: there is no difference to add")
            return False
        return True

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if not self.filepath:
            self.filepath = f"{bpy.path.clean_name(context.scene.world.name)}_edited.exr"
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}

    def execute(self, context: bpy.types.Context) -> set[str]:
        if not self.filepath:
            self.report({'ERROR'}, "No file path given")
            return {'CANCELLED'}
        path = bpy.path.ensure_ext(bpy.path.abspath(self.filepath), ".exr")
        scene = context.scene
        try:
            from ..addon.blender import reader
            from ..addon.io import exr

            difference = world_layer.image_rgb(world_layer.layer_image(scene.world))
            hdri = reader.read_scene(scene, center=session.probe_center(scene.dimred)).hdri
            if hdri.shape != difference.shape:
                raise DimredError(
                    f"The difference image is {difference.shape[1]}x{difference.shape[0]} but the HDRI is "
                    f"{hdri.shape[1]}x{hdri.shape[0]}: run Remove again"
                )
            exr.write_exr(path, hdri + difference)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        except OSError as error:
            self.report({'ERROR'}, f"Could not write {path}: {error}")
            return {'CANCELLED'}
        self.report({'INFO'}, f"Wrote {path}")
        return {'FINISHED'}


classes = (DIMRED_OT_remove, DIMRED_OT_cancel, DIMRED_OT_clear, DIMRED_OT_save_hdri)

register, unregister = bpy.utils.register_classes_factory(classes)
