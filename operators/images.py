"""Operators for the images beside a removal: show the diagnostics picture, make a mask to paint."""
from __future__ import annotations

import bpy

from ..addon.errors import DimredError
from .support import pictures

# The largest mask width made: a quarter of a 16K panorama paints and loads far faster, and the
# mask may be any integer fraction of the panorama's size.
MASK_MAX_WIDTH = 4096


class DIMRED_OT_show_diagnostics(bpy.types.Operator):
    bl_idname = "dimred.show_diagnostics"
    bl_label = "Show Diagnostics"
    bl_description = (
        "Open the picture of how the proxy fits the photograph in an Image Editor: cyan the proxy's outline, "
        "yellow the photographed object's; red object the proxy misses, blue proxy over no object"
    )
    bl_options = {'REGISTER'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if bpy.data.images.get(pictures.DIAGNOSTICS_IMAGE) is None:
            cls.poll_message_set("Run Remove, Relocate or Align to Photo first")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        image = bpy.data.images[pictures.DIAGNOSTICS_IMAGE]
        if not pictures.show_in_editor(context, image):
            self.report({'INFO'}, f"No window to show it in: the picture is the image '{image.name}'")
        return {'FINISHED'}


class DIMRED_OT_new_mask(bpy.types.Operator):
    bl_idname = "dimred.new_mask"
    bl_label = "New Mask"
    bl_description = (
        "Make a transparent mask the panorama's size (a whole fraction of it, at most 4096 pixels wide) to paint "
        "in the Image Editor: white adds to the region the removal fills, black takes away"
    )
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if context.scene is None or context.scene.world is None:
            cls.poll_message_set("The scene has no World: light it with the panorama first")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        from ..addon.blender import reader

        try:
            width, height = reader.panorama_size(context.scene)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        factor = mask_factor(width, height)
        # 8-bit, so that painted grey stays the grey painted (a float image would hold it linearised).
        image = bpy.data.images.new("Dimred Mask", width // factor, height // factor, alpha=True)
        image.generated_color = (0.0, 0.0, 0.0, 0.0)  # transparent: the computed region as it is
        context.scene.dimred.mask_image = image
        pictures.show_in_editor(context, image, paint=True)
        self.report({'INFO'}, f"Mask '{image.name}' {image.size[0]}x{image.size[1]}: paint white to add, black to "
                              "take away")
        return {'FINISHED'}


def mask_factor(width: int, height: int) -> int:
    """The smallest whole factor dividing both sides that brings the width to MASK_MAX_WIDTH or
    less (1 where none does)."""
    return next((f for f in range(-(-width // MASK_MAX_WIDTH), width + 1) if width % f == 0 and height % f == 0), 1)


classes = (DIMRED_OT_show_diagnostics, DIMRED_OT_new_mask)

register, unregister = bpy.utils.register_classes_factory(classes)
