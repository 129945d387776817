"""When only engine tests run (`pytest tests/engine`, `./dev test --quick`), Blender's modules
and the Cycles renderer of the ground truths (`scenes.render`) cannot be imported.

The engine is numpy-only so that it runs outside Blender (the command line's worker, CI without
Blender); an engine test that needs bpy, even indirectly through a helper, would hide a
dependency the layering forbids. A run that also collects Blender-side tests leaves the import
system alone, since those tests need bpy.
"""
from __future__ import annotations

import importlib.abc
import sys
from pathlib import Path

import pytest

ENGINE_TESTS = Path(__file__).resolve().parent
BLENDER_MODULES = ("bpy", "bmesh", "mathutils", "bl_math", "bl_ui", "bl_operators", "bpy_extras", "gpu")
# Renders belong to the ground-truth tests: the engine's tier stays free of Cycles' minutes.
RENDERERS = ("scenes.render", "scenes.render_job")


class NoBlender(importlib.abc.MetaPathFinder):
    """Refuses Blender's modules and the renderer, so that importing one fails the test that tried."""

    def find_spec(self, fullname: str, path=None, target=None):
        if fullname.split(".")[0] in BLENDER_MODULES or fullname in RENDERERS:
            raise ImportError(f"engine tests run without Blender: '{fullname}' may not be imported")
        return None


def _only_engine_tests(config: pytest.Config) -> bool:
    base = config.invocation_params.dir
    paths = [(base / arg.split("::")[0]).resolve() for arg in config.args]
    return bool(paths) and all(p.is_relative_to(ENGINE_TESTS) for p in paths)


def pytest_configure(config: pytest.Config) -> None:
    if _only_engine_tests(config) and not any(name in sys.modules for name in BLENDER_MODULES):
        sys.meta_path.insert(0, NoBlender())
