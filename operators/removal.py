"""Operators that run the removal and manage its result: remove, clear, save HDRI.

This first version runs synchronously on the main thread. The engine (`addon.bridge`,
`addon.pipeline`, `addon.exr`) is imported inside `execute`, so registering the add-on costs
nothing and does not depend on it.
"""
from __future__ import annotations

import json
import os

import bpy
from bpy.props import BoolProperty, StringProperty

from ..addon.errors import DimredError
from . import world_layer


def _probe_center(settings: bpy.types.PropertyGroup) -> tuple[float, float, float] | None:
    # None lets the bridge apply the contract's fallbacks (an Empty named ProbeCenter, the origin).
    return tuple(settings.probe_center) if settings.use_probe_center else None


def output_folder(settings: bpy.types.PropertyGroup) -> str:
    """The absolute output folder; a '//' path needs a saved .blend to be relative to."""
    raw = settings.output_dir.strip() or "//"
    if raw.startswith("//") and not bpy.data.filepath:
        raise DimredError(
            f"The output folder '{raw}' is relative to the .blend file, which is not saved yet: "
            "save it first or choose an absolute folder"
        )
    return os.path.normpath(bpy.path.abspath(raw))


def difference_filename(world: bpy.types.World) -> str:
    """One difference file per world, so scenes sharing an output folder do not collide."""
    return f"{bpy.path.clean_name(world.name)}_difference.exr"


def _world_poll(cls: type[bpy.types.Operator], context: bpy.types.Context) -> bool:
    if context.scene is None or context.scene.world is None:
        cls.poll_message_set("The scene has no World: light it with the panorama first")
        return False
    return True


def report_summary(report: dict) -> str:
    """One line about a run's report dict (fields per the command line's report.json)."""
    total = report.get("seconds", {}).get("total")
    parts = [f"{total:.1f} s" if isinstance(total, (int, float)) else "done"]
    for key, label in (("skipped", "stages skipped"), ("warnings", "warnings")):
        if report.get(key):
            parts.append(f"{len(report[key])} {label}")
    return ", ".join(parts)


class DIMRED_OT_remove(bpy.types.Operator):
    bl_idname = "dimred.remove"
    bl_label = "Remove Object"
    bl_description = (
        "Compute the difference image that removes the marked object, its shadow and its reflected "
        "light from the panorama, and show HDRI + difference in the world"
    )
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if not _world_poll(cls, context):
            return False
        if context.scene.dimred.target is None:
            cls.poll_message_set("Mark the object to remove first")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        scene = context.scene
        settings, world = scene.dimred, scene.world
        try:
            folder = output_folder(settings)
            # Check the world before the long computation, not after it.
            world_layer.world_nodes(world)
            from ..addon import bridge, exr, pipeline

            # The same checks as the command line, so both refuse the same input.
            bridge.check_object(scene, settings.target.name)
            for name in settings.surface_names():
                bridge.check_object(scene, name, purpose="used as a target surface")
            scene_data = bridge.read_scene(scene, _probe_center(settings))
            result = pipeline.remove_object(
                scene_data,
                settings.target.name,
                planes=settings.surface_names(),
                quality=settings.quality,
            )
            os.makedirs(folder, exist_ok=True)
            path = os.path.join(folder, difference_filename(world))
            exr.write_exr(path, result.difference)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        except OSError as error:
            self.report({'ERROR'}, f"Could not write the difference image: {error}")
            return {'CANCELLED'}

        # A folder given relative to the .blend stays relative, so the file can move with it.
        relative = settings.output_dir.strip().startswith("//")
        image_path = bpy.path.relpath(path) if relative else path
        world_layer.add_layer(world, world_layer.load_difference_image(image_path, difference_filename(world)))
        settings.last_report = json.dumps(result.report)
        self.report({'INFO'}, f"Removed '{settings.target.name}': {report_summary(result.report)}; wrote {path}")
        return {'FINISHED'}


class DIMRED_OT_clear(bpy.types.Operator):
    bl_idname = "dimred.clear"
    bl_label = "Clear Removal"
    bl_description = "Remove the difference layer from the world and show the original panorama again"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if not _world_poll(cls, context):
            return False
        if not world_layer.has_layer(context.scene.world):
            cls.poll_message_set("The world shows no removal")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        image = world_layer.remove_layer(context.scene.world)
        if image is not None and image.users == 0:
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
        if not _world_poll(cls, context):
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
            from ..addon import bridge, exr

            difference = world_layer.image_rgb(world_layer.layer_image(scene.world))
            hdri = bridge.read_scene(scene, _probe_center(scene.dimred)).hdri
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


classes = (DIMRED_OT_remove, DIMRED_OT_clear, DIMRED_OT_save_hdri)

register, unregister = bpy.utils.register_classes_factory(classes)
