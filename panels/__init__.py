"""The 3D Viewport sidebar tab "Diminished Reality"."""
from __future__ import annotations

from . import sidebar

_modules = (sidebar,)


def register() -> None:
    for module in _modules:
        module.register()


def unregister() -> None:
    for module in reversed(_modules):
        module.unregister()
