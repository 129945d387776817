"""Align to Photo: fit the marked proxy's pose on its support to the object's outline in the
panorama (`addon.alignment.fit`) and move the proxy there.

The fit takes about a second at 1K, so it runs on the main thread under a wait cursor, not in a
worker. The panorama is read as a removal reads it (earlier removed objects left out of the
room); an object standing where a relocation put it is refused, since its photographed place
is no longer where it stands.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

import bpy
from mathutils import Matrix

from ..addon.errors import DimredError
from .run_operator import target_poll
from .support import pictures, session

if TYPE_CHECKING:  # the engine is imported only when a run starts
    from ..addon.alignment.fit import Alignment
    from ..addon.segmentation.seen import SeenObject


def fit_to_photo(scene: bpy.types.Scene, name: str) -> tuple[Alignment, SeenObject | None]:
    """The alignment of object `name` to the scene's panorama and the object as the photograph
    shows it at the fitted pose; DimredError when it cannot be aligned."""
    from ..addon import memory, pipeline
    from ..addon.blender import reader
    from ..addon.run.job import loaded

    settings = scene.dimred
    reader.check_object(scene, name, purpose="aligned")
    if session.relocated_matrix(settings, name) is not None:
        raise DimredError(f"'{name}' stands where its relocation put it, not where the panorama shows it: "
                          "Clear first, then align it at its photographed place")
    memory.check_fits(*reader.panorama_size(scene), quality=settings.quality)
    data = loaded(session.engine_scene(scene, name))
    alignment = pipeline.align_to_photo(data, name, quality=settings.quality, fit_height=settings.fit_height)
    moved = alignment.moved(data, data.object_index(name))
    return alignment, pipeline.photographed_object(moved, name, quality=settings.quality)


class DIMRED_OT_align(bpy.types.Operator):
    bl_idname = "dimred.align"
    bl_label = "Align to Photo"
    bl_description = (
        "Fit the marked proxy to the object's outline in the panorama: a shift along its support, a turn about "
        "the vertical and a scale (or, with Fit Support Height, the support's height). The Diagnostics picture "
        "shows the fit"
    )
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if not target_poll(cls, context):
            return False
        tree = context.scene.world.node_tree
        if tree is None or not any(n.type == 'TEX_ENVIRONMENT' and n.image is not None for n in tree.nodes):
            cls.poll_message_set("The World shows no panorama: add an Environment Texture with the HDRI")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        scene = context.scene
        settings = scene.dimred
        obj = settings.target
        window = None if bpy.app.background else context.window
        if window is not None:
            window.cursor_modal_set('WAIT')
        try:
            alignment, seen = fit_to_photo(scene, obj.name)
            picture = pictures.diagnostics_picture(seen)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        finally:
            if window is not None:
                window.cursor_modal_restore()
        # The picture shows a fit that was not applied too: it says why.
        if picture is not None:
            pictures.show_diagnostics(picture)
        settings.photo_fit = session.photo_fit(obj.name, seen.summary() if seen else None, alignment.summary())
        if not alignment.applied:
            self.report({'INFO'} if alignment.fits else {'WARNING'}, alignment.message)
            return {'CANCELLED'}
        correction = Matrix(alignment.matrix.tolist())
        obj.matrix_world = correction @ obj.matrix_world
        settings.correct_marked(obj.name, correction)
        self.report({'INFO'}, alignment.message)
        return {'FINISHED'}


classes = (DIMRED_OT_align,)

register, unregister = bpy.utils.register_classes_factory(classes)
