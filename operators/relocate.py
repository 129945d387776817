"""The Relocate operator: move the marked object under the fixed-view constraint (docs/design.md).

The move is a yaw about the vertical axis through the probe centre and a factor on the
object's horizontal distance from it, both counted from where the panorama shows the object
(its photographed place, kept by the list of removals once it has been relocated). The run
itself is Remove's (`run_operator.RunOperator`): synchronous from scripts and in background mode,
threaded with progress when the interactive tool confirms. On success the object stands at its
new place, so the proxy geometry matches the new panorama and later removals see it there.

Invoked from the UI without values, the operator first runs an interactive tool in the style
of Blender's transform tools (`relocate_input`): the object follows the mouse in the viewport
and the area header shows the move and the residual change of view elevation; Esc puts the
object back exactly.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import bpy
import numpy as np
from bpy.props import BoolProperty, FloatProperty
from mathutils import Matrix

from ..addon.errors import DimredError
from .run_operator import RunOperator
from .settings import DISTANCE_DESCRIPTION, YAW_DESCRIPTION
from .support import session
from .support.relocate_input import RelocateInput

if TYPE_CHECKING:  # the engine is imported only when a run starts
    from ..addon.relocation.fixedview import Move
    from ..addon.scene import SceneData

# The channels that setting matrix_world rewrites: restored one by one, a cancel leaves the
# object bit for bit as it was (a matrix would be decomposed again, with rounding).
_TRANSFORM_CHANNELS = ("location", "rotation_euler", "rotation_quaternion", "rotation_axis_angle", "scale")


@dataclass
class Placement:
    """Where the marked object may go: its photographed matrix, the probe centre and the
    reference point whose distance the factor scales (as the engine computes them)."""

    object_name: str
    photographed: Matrix
    center: np.ndarray
    reference: np.ndarray
    scene: SceneData  # the geometry as the engine will see it, for `refusal`

    @classmethod
    def of_target(cls, context: bpy.types.Context, *, photographed: Matrix | None = None) -> Placement:
        """The placement of `scene.dimred.target` from `photographed` (by default
        `session.photographed_matrix`); DimredError when it cannot be moved."""
        from ..addon.blender import reader
        from ..addon.relocation.fixedview import reference_point

        scene, settings = context.scene, context.scene.dimred
        obj = settings.target
        reader.check_object(scene, obj.name, purpose="relocated")
        if photographed is None:
            photographed = session.photographed_matrix(settings, obj)
        data = session.engine_scene(scene, obj.name, photographed)
        reference = reference_point(data.triangles[data.tri_object == data.object_index(obj.name)])
        return cls(obj.name, photographed, data.center, reference, data)

    def matrix(self, move: Move) -> Matrix:
        """The object's world matrix after `move`."""
        from ..addon.relocation.fixedview import move_matrix

        return Matrix(move_matrix(self.center, self.reference, move).tolist()) @ self.photographed

    def refusal(self, move: Move) -> str:
        """Why the engine would refuse `move` (off the support surface, into a wall or another
        object), or '': checked as the mouse moves, so the tool never confirms a place the run
        would refuse."""
        from ..addon.errors import DimredError
        from ..addon.relocation.placement import place

        try:
            place(self.scene, self.scene.object_index(self.object_name), move)
        except DimredError as error:
            return str(error)
        return ""

    def elevation_change(self, move: Move) -> float:
        from ..addon.relocation.fixedview import elevation_change

        return elevation_change(self.center, self.reference, move)


def transform_move(context: bpy.types.Context) -> tuple[Move, Matrix]:
    """The move the artist made by hand: from the marked object's photographed matrix (its
    relocation's, else where it stood when marked) to where it stands now, and that matrix;
    DimredError for a move the fixed-view constraint forbids (a tilt, a lift, a scale, a turn
    that is not the orbit)."""
    from ..addon.blender import reader
    from ..addon.relocation.fixedview import move_between

    settings = context.scene.dimred
    obj = settings.target
    reader.check_object(context.scene, obj.name, purpose="relocated")
    photographed = session.relocated_matrix(settings, obj.name)
    if photographed is None:
        photographed = settings.marked_placement()
    if photographed is None:
        raise DimredError(f"'{obj.name}' has no recorded photographed place: mark it (Mark Object to Remove) "
                          "where the photograph shows it, then move it")
    if obj.matrix_world == photographed:
        raise DimredError(f"'{obj.name}' stands where the panorama shows it: move it with G and R first, or give "
                          "a yaw and a distance factor")
    placement = Placement.of_target(context, photographed=photographed)
    move = move_between(placement.center, placement.reference, np.array(photographed), np.array(obj.matrix_world))
    return move, photographed


def snapshot(obj: bpy.types.Object) -> dict[str, tuple[float, ...]]:
    """The transform channels that setting matrix_world rewrites, for `restore`."""
    return {name: tuple(getattr(obj, name)) for name in _TRANSFORM_CHANNELS}


def restore(obj: bpy.types.Object, saved: dict[str, tuple[float, ...]]) -> None:
    for name, value in saved.items():
        setattr(obj, name, value)


def _move(yaw: float, distance_scale: float) -> Move:
    from ..addon.relocation.fixedview import Move

    return Move(yaw=yaw, distance_scale=distance_scale)


class DIMRED_OT_relocate(RunOperator, bpy.types.Operator):
    bl_idname = "dimred.relocate"
    bl_label = "Relocate Object"
    bl_description = (
        "Move the marked object in the panorama: turn it about the vertical axis through the probe centre "
        "and scale its distance, so the photographed side keeps facing the probe. Interactive from the "
        "panel (mouse, typed values, Enter/Esc); then computed in the background like Remove"
    )
    bl_options = {'REGISTER', 'UNDO'}

    # SKIP_SAVE: values given explicitly skip the interactive tool, remembered ones must not.
    yaw: FloatProperty(name="Yaw", description=YAW_DESCRIPTION, precision=1, options={'SKIP_SAVE'})
    distance_scale: FloatProperty(name="Distance", description=DISTANCE_DESCRIPTION, default=1.0, precision=2,
                                  step=1, options={'SKIP_SAVE'})

    _tool: RelocateInput | None = None
    _placement: Placement | None = None
    _saved: dict | None = None  # the object's transform channels before the tool moved it

    from_transform: BoolProperty(
        name="From Transform",
        description=(
            "Take the move from where the object stands now, moved with G and R in the viewport, measured from "
            "where it stood when it was marked (or from its photographed place once relocated). Refused unless "
            "it turns the object about the probe centre's vertical axis by the angle it goes round it, and keeps "
            "its height and size"
        ),
        options={'SKIP_SAVE'},
    )

    @classmethod
    def description(cls, context: bpy.types.Context, properties: bpy.types.OperatorProperties) -> str:
        if properties.from_transform:
            return ("Relocate the marked object to where it stands now: move it with G and R in the viewport first "
                    "(turning it about the probe centre's vertical axis by the angle it goes round it, at its "
                    "height), then compute the panorama for that place")
        return cls.bl_description

    def plan(self, context: bpy.types.Context) -> tuple[Move, Matrix | None]:
        if not self.from_transform:
            return _move(self.yaw, self.distance_scale), None
        move, photographed = transform_move(context)
        self.yaw, self.distance_scale = move.yaw, move.distance_scale
        return move, photographed

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        given = self.from_transform or any(self.properties.is_property_set(name) for name in ("yaw", "distance_scale"))
        if given or bpy.app.background or context.window is None:
            return super().invoke(context, event)
        try:
            self._placement = Placement.of_target(context)
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        settings = context.scene.dimred
        self._saved = snapshot(settings.target)
        self._tool = RelocateInput.starting_at(settings.yaw, settings.distance_scale,
                                               mouse=(event.mouse_x, event.mouse_y))
        self._show(context)
        context.window_manager.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def modal(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if self._tool is None:
            return super().modal(context, event)  # the run after the tool confirmed
        action = self._tool.handle(event)
        if action == "PASS":
            return {'PASS_THROUGH'}
        if action == "UPDATE":
            self._show(context)
        elif action == "CANCEL":
            self._end_tool(context)
            return {'CANCELLED'}
        elif action == "CONFIRM":
            self.yaw, self.distance_scale = self._tool.yaw, self._tool.distance_scale
            # The run starts from the scene as it was: the object moves when the result is applied.
            self._end_tool(context)
            return {'RUNNING_MODAL'} if self._launch(context) else {'CANCELLED'}
        return {'RUNNING_MODAL'}

    def cancel(self, context: bpy.types.Context) -> None:
        if self._tool is not None:
            self._end_tool(context)
        super().cancel(context)

    def _finish(self, run: session.RemovalSession, ok: bool, context: bpy.types.Context | None = None) -> set[str]:
        if ok:
            # The panel's fields keep the last relocation, where the tool starts next time.
            settings = bpy.data.scenes[run.scene_name].dimred
            settings.yaw, settings.distance_scale = self.yaw, self.distance_scale
        return super()._finish(run, ok, context)

    def _show(self, context: bpy.types.Context) -> None:
        """Put the object where the tool's values take it and say so in the header."""
        tool, placement = self._tool, self._placement
        elevation = None
        tool.refusal = ""
        if not tool.error:
            move = _move(tool.yaw, tool.distance_scale)
            tool.refusal = placement.refusal(move)
            context.scene.objects[placement.object_name].matrix_world = placement.matrix(move)
            elevation = placement.elevation_change(move)
        if context.area is not None:
            context.area.header_text_set(tool.header(placement.object_name, elevation))

    def _end_tool(self, context: bpy.types.Context) -> None:
        obj = context.scene.objects.get(self._placement.object_name)
        if obj is not None:
            restore(obj, self._saved)
        if context.area is not None:
            context.area.header_text_set(None)
        self._tool = self._placement = self._saved = None


classes = (DIMRED_OT_relocate,)

register, unregister = bpy.utils.register_classes_factory(classes)
