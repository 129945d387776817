"""The layering, read from the source: the engine imports no Blender module, and the add-on's
Blender side reaches the engine only through the extension's own package.

The engine (`addon/`, except `addon/blender/`, the bridge that reads Blender data) must run
without Blender: the command line's worker, the benchmarks and the engine tests import it with
numpy alone. Every import statement counts, at module level or inside a function, since a lazy
`import bpy` fails the same way the first time that code runs outside Blender.

The operators and panels run inside the installed extension (`bl_ext.<repo>.diminished_reality`),
where no top-level package `addon` exists: an absolute `import addon.X` there works in a checkout
and fails once installed, so they must import the engine relatively (`from ..addon import X`).
"""
from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
ENGINE = ROOT / "addon"
BRIDGE = ENGINE / "blender"
# Blender's own Python modules (bl_* covers bl_math, bl_ui, bl_operators, bl_ext ...).
BLENDER_MODULES = frozenset({"bpy", "bmesh", "mathutils", "bpy_extras", "gpu", "gpu_extras", "aud", "freestyle",
                             "idprop"})
# `python -m addon.cli` is the command line's entry point: it reads the .blend through Blender,
# so it alone outside the bridge hands over to it.
BRIDGE_USERS = frozenset({ENGINE / "cli.py"})
ADD_ON_SIDE = [ROOT / "__init__.py", *sorted((ROOT / "operators").rglob("*.py")),
               *sorted((ROOT / "panels").rglob("*.py"))]


def _relative(path: Path) -> str:
    return path.relative_to(ROOT).as_posix()


def _engine_modules() -> list[Path]:
    return [p for p in sorted(ENGINE.rglob("*.py")) if BRIDGE not in p.parents]


def _imports(path: Path) -> Iterator[tuple[int, int, str]]:
    """(line, level, module) of every import in `path`: `import a.b` and `from a.b import c`
    give 'a.b' (level 0), `from ..a import b` gives 'a' with level 2 and `from .. import b`
    gives 'b'; `__import__('a')` and `importlib.import_module('a')` with a literal name count."""
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield node.lineno, 0, alias.name
        elif isinstance(node, ast.ImportFrom):
            if node.module:
                yield node.lineno, node.level, node.module
            else:
                for alias in node.names:
                    yield node.lineno, node.level, alias.name
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            func = node.func
            name = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""
            if name in ("__import__", "import_module") and isinstance(node.args[0].value, str):
                yield node.lineno, 0, node.args[0].value


def _is_blender_module(module: str) -> bool:
    top = module.split(".")[0]
    return top in BLENDER_MODULES or top.startswith("bl_")


def _resolve(path: Path, level: int, module: str) -> str:
    """The absolute dotted name, from the repository root, that an import in `path` names."""
    if level == 0:
        return module
    package = path.parent.relative_to(ROOT).parts
    base = package[:len(package) - (level - 1)] if level > 1 else package
    return ".".join([*base, module])


def test_the_layering_test_sees_every_kind_of_import(tmp_path):
    """The checks below are only as good as `_imports`: it must see imports in function bodies,
    relative imports and imports by name."""
    probe = tmp_path / "probe.py"
    probe.write_text(
        "import os, bpy.types\n"
        "from .. import mathutils\n"
        "def later():\n"
        "    from bl_math import clamp\n"
        "    import importlib\n"
        "    return importlib.import_module('bmesh'), __import__('gpu')\n"
    )
    found = {module for _, _, module in _imports(probe)}
    assert {"os", "bpy.types", "mathutils", "bl_math", "importlib", "bmesh", "gpu"} <= found
    assert {m for m in found if _is_blender_module(m)} == {"bpy.types", "mathutils", "bl_math", "bmesh", "gpu"}


def test_there_are_engine_modules_and_a_bridge_to_check():
    modules = {_relative(p) for p in _engine_modules()}
    assert {"addon/scene.py", "addon/pipeline.py", "addon/geometry/latlong.py"} <= modules
    assert (BRIDGE / "reader.py").is_file()
    assert ADD_ON_SIDE[0].is_file() and len(ADD_ON_SIDE) > 3


@pytest.mark.parametrize("path", _engine_modules(), ids=_relative)
def test_the_engine_imports_no_blender_module(path):
    found = [f"line {line}: {module}" for line, level, module in _imports(path)
             if level == 0 and _is_blender_module(module)]
    assert not found, f"{_relative(path)} imports Blender outside addon/blender/: {found}"


@pytest.mark.parametrize("path", [p for p in _engine_modules() if p not in BRIDGE_USERS], ids=_relative)
def test_the_engine_does_not_import_the_bridge(path):
    """The bridge imports bpy; an engine module importing it needs Blender just the same."""
    found = [f"line {line}: {_resolve(path, level, module)}" for line, level, module in _imports(path)
             if _resolve(path, level, module).split(".")[:2] == ["addon", "blender"]]
    assert not found, f"{_relative(path)} imports the bridge: {found}"


@pytest.mark.parametrize("path", ADD_ON_SIDE, ids=_relative)
def test_the_add_on_side_imports_the_engine_only_relatively(path):
    found = [f"line {line}: {module}" for line, level, module in _imports(path)
             if level == 0 and module.split(".")[0] == "addon"]
    assert not found, f"{_relative(path)} imports the engine absolutely (fails once installed): {found}"
