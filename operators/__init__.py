"""The `scene.dimred` settings and the `bpy.ops.dimred.*` operators, registered in order."""
from __future__ import annotations

from . import align, images, marking, relocate, remove, room, room_settings, settings
from .support import session, warmup

# Settings first: the operators and the panel read scene.dimred.
_modules = (settings, room_settings, session, warmup, marking, remove, relocate, align, images, room)


def register() -> None:
    for module in _modules:
        module.register()


def unregister() -> None:
    for module in reversed(_modules):
        module.unregister()
