"""One process, one engine: the extension's `diminished_reality.addon` is the `addon` package
the engine tests import, module for module (tests/blender/conftest.py, `EngineAlias`).

With two copies an engine error raised under the operators would be a class the tests cannot
catch as `addon.errors.DimredError`, and a test patching `addon.X` would patch a module the
operators never call.
"""
from __future__ import annotations

import sys

import bpy
import pytest

import addon.errors
import addon.relocation.placement


def test_the_extension_imports_the_engine_modules_the_tests_import(registered):
    import diminished_reality.addon.errors  # noqa: F401  (the operators import it on registration anyway)

    assert sys.modules["diminished_reality.addon.errors"] is sys.modules["addon.errors"]
    aliased = {name: module for name, module in sys.modules.items() if name.startswith("diminished_reality.addon")}
    assert "diminished_reality.addon" in aliased
    for name, module in aliased.items():
        engine_name = name.removeprefix("diminished_reality.")
        assert module is sys.modules[engine_name], name
        assert module.__spec__.name == engine_name, f"{name} carries the alias's spec"


def test_an_engine_module_imported_first_through_the_extension_is_the_same_module(registered):
    from addon.geometry import clusters
    from diminished_reality.addon.geometry import clusters as through_extension

    assert through_extension is clusters


def test_an_engine_error_inside_an_operator_is_the_engines_dimred_error(room):
    from diminished_reality.operators import relocate

    bpy.data.objects["Box"].hide_render = True
    with pytest.raises(addon.errors.DimredError, match="hidden for render"):
        relocate.Placement.of_target(bpy.context)


def test_patching_an_engine_module_patches_what_the_operators_call(room, monkeypatch):
    from diminished_reality.addon.relocation.fixedview import Move
    from diminished_reality.operators import relocate

    placement = relocate.Placement.of_target(bpy.context)

    def refuse(*_args, **_kwargs):
        raise addon.errors.DimredError("refused by the test's patch")

    monkeypatch.setattr(addon.relocation.placement, "place", refuse)
    assert placement.refusal(Move(yaw=30.0, distance_scale=1.0)) == "refused by the test's patch"
