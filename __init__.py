"""Diminished Reality: remove a real object from the HDR light probe that lights the scene.

The extension's entry point. `register()` adds the settings, operators and sidebar panel, and
the command line command `blender -b SCENE.blend -c dimred ...`. The numpy engine in `addon/`
is imported only when an operator or the command runs, so enabling the add-on stays cheap.
"""
from __future__ import annotations

import bpy

from . import operators, panels

_modules = (operators, panels)
_cli_handle = None


def _dimred_command(argv: list[str]) -> int:
    """`blender -c dimred ARGS`: imports the command line only when it is actually used."""
    from .addon.blender.cli import blender_command

    return blender_command(argv)


def register() -> None:
    global _cli_handle
    for module in _modules:
        module.register()
    _cli_handle = bpy.utils.register_cli_command("dimred", _dimred_command)


def unregister() -> None:
    global _cli_handle
    if _cli_handle is not None:
        bpy.utils.unregister_cli_command(_cli_handle)
        _cli_handle = None
    for module in reversed(_modules):
        module.unregister()
