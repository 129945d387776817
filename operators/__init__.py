"""The `scene.dimred` settings and the `bpy.ops.dimred.*` operators, registered in order."""
from __future__ import annotations

from . import align, images, marking, relocate, remove, settings
from .support import session, warmup

# Settings first: the operators and the panel read scene.dimred.
_modules = (settings, session, warmup, marking, remove, relocate, align, images)


def register() -> None:
    for module in _modules:
        module.register()


def unregister() -> None:
    for module in reversed(_modules):
        module.unregister()
