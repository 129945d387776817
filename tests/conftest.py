"""Collection of the whole suite: the repository root is not imported as a test package.

The repository root is the extension's package: its `__init__.py` imports bpy and, through the
operators, engine modules. pytest sees that file, makes the root a `Package` node and, before the
first test, imports it under the checkout folder's name (`main`, say) only to look for a
`setup_module` there. That import would give every run a second copy of the extension and of
the engine modules it imports (a second `DimredError` class), and would import bpy into engine
runs, which must show that the engine works without it. Tests import the extension themselves,
as `diminished_reality` (tests/blender/conftest.py); the root package has no module-level
setup, so its setup is skipped.

Fixtures live next to the tests that use them: tests/blender/conftest.py (Blender sessions, the
extension, the tiny room in Blender) and tests/engine/conftest.py (engine runs without bpy).
"""
from __future__ import annotations

import pytest


def _skip_setup() -> None:
    """The repository root's setup: nothing (see the module docstring)."""


def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config, items: list[pytest.Item]) -> None:
    for node in {node for item in items for node in item.listchain()}:
        if isinstance(node, pytest.Package) and node.path == config.rootpath:
            node.setup = _skip_setup
    # `./dev test` hands whole modules to two workers as they come free (pytest-xdist,
    # --dist loadfile): the longest first, or one started last would leave the other worker
    # idle for minutes. Each module's tests stay together and in their order.
    slow = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: (_rank(item.path.stem), item.path not in slow))


# The modules that take minutes on two cores from a clean clone (their renders included), longest
# first; then every module with a slow test, then the rest, in collection order.
_LONGEST = ("test_relocation_groundtruth", "test_rough_proxy_groundtruth", "test_batch_groundtruth",
            "test_full_resolution_groundtruth", "test_removal_groundtruth")


def _rank(module: str) -> int:
    return _LONGEST.index(module) if module in _LONGEST else len(_LONGEST)
