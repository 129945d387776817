"""The run that Remove and Relocate share: synchronous from `execute` (scripts, `blender -b`),
threaded from `invoke` (a worker thread polled by a modal operator on a timer; Esc cancels)."""
from __future__ import annotations

from typing import TYPE_CHECKING

import bpy

from ..addon.errors import DimredError
from .support import session

if TYPE_CHECKING:  # the engine is imported only when a run starts
    from mathutils import Matrix

    from ..addon.relocation.fixedview import Move

# Seconds between the modal operator's polls of the worker: fast enough that Esc acts at once
# and progress moves smoothly, slow enough to cost nothing.
POLL_INTERVAL = 0.05


def world_poll(cls: type[bpy.types.Operator], context: bpy.types.Context) -> bool:
    if context.scene is None or context.scene.world is None:
        cls.poll_message_set("The scene has no World: light it with the panorama first")
        return False
    return True


def target_poll(cls: type[bpy.types.Operator], context: bpy.types.Context) -> bool:
    """A World, a marked object and no removal running: what a run on the marked object needs."""
    if not world_poll(cls, context):
        return False
    if context.scene.dimred.target is None:
        cls.poll_message_set("Mark the object to remove first")
        return False
    if session.active() is not None:
        cls.poll_message_set("A removal is already running: wait for it or cancel it")
        return False
    return True


class RunOperator:
    """What Remove and Relocate share: a run of `session.RemovalSession`, synchronous from
    `execute` and threaded from `invoke` (a modal operator polling it on a timer, Esc cancels).

    Subclasses say what to run with `plan` (no move: remove)."""

    _timer = None
    _session: session.RemovalSession | None = None

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return target_poll(cls, context)

    def plan(self, context: bpy.types.Context) -> tuple[Move | None, Matrix | None]:
        """The move to run (None: remove) and the object's photographed matrix (None: the
        session's default); DimredError when the request is refused."""
        return None, None

    def execute(self, context: bpy.types.Context) -> set[str]:
        try:
            run = session.RemovalSession.begin(context, *self.plan(context))
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return {'CANCELLED'}
        return self._finish(run, run.run_here(context))

    def invoke(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        if bpy.app.background or context.window is None:
            return self.execute(context)
        if not self._launch(context):
            return {'CANCELLED'}
        context.window_manager.modal_handler_add(self)
        return {'RUNNING_MODAL'}

    def _launch(self, context: bpy.types.Context) -> bool:
        """Begin the session in a worker thread and poll it on a timer; False (reported) when
        the input is refused."""
        try:
            self._session = session.RemovalSession.begin(context, *self.plan(context))
        except DimredError as error:
            self.report({'ERROR'}, str(error))
            return False
        self._session.start()
        self._timer = context.window_manager.event_timer_add(POLL_INTERVAL, window=context.window)
        self._status(context)
        return True

    def modal(self, context: bpy.types.Context, event: bpy.types.Event) -> set[str]:
        run = self._session
        if event.type == 'ESC' or run.worker.cancelled:
            run.cancel(context)
            return self._finish(run, False, context)
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        state = run.tick(context)
        if state == 'RUNNING':
            self._status(context)
            return {'RUNNING_MODAL'}
        return self._finish(run, state == 'FINISHED', context)

    def cancel(self, context: bpy.types.Context) -> None:
        # Blender ends the modal operator (file load, window closed): stop the worker first.
        if self._session is not None:
            self._session.cancel(context)
            self._finish(self._session, False, context)

    def _status(self, context: bpy.types.Context) -> None:
        run = self._session
        context.workspace.status_text_set(
            f"Diminished Reality: {run.stage.replace('_', ' ')} {100 * run.fraction:.0f} %   (Esc to cancel)")

    def _finish(self, run: session.RemovalSession, ok: bool, context: bpy.types.Context | None = None) -> set[str]:
        if self._timer is not None and context is not None:
            context.window_manager.event_timer_remove(self._timer)
            self._timer = None
            context.workspace.status_text_set(None)
        self._session = None
        self.report({'INFO'} if ok else {'ERROR'}, run.message)
        return {'FINISHED'} if ok else {'CANCELLED'}
