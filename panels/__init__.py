"""The 3D Viewport sidebar tab "Diminished Reality"."""
from __future__ import annotations

from . import room, sidebar

_modules = (sidebar, room)


def register() -> None:
    for module in _modules:
        module.register()


def unregister() -> None:
    for module in reversed(_modules):
        module.unregister()
