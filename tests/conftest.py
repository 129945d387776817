"""Collection of the whole suite: the repository root is not imported as a test package.

The repository root is the extension's package: its `__init__.py` imports bpy and, through the
operators, engine modules. pytest sees that file, makes the root a `Package` node and, before the
first test, imports it under the checkout folder's name (`main`, say) only to look for a
`setup_module` there. That import would give every run a second copy of the extension and of
the engine modules it imports (a second `DimredError` class), and would import bpy into engine
runs, which must show that the engine works without it. Tests import the extension themselves,
as `diminished_reality` (tests/blender/conftest.py); the root package has no module-level
setup, so its setup is skipped.

The order of the modules follows tests/durations.json, each module's seconds measured in a
whole run (`./dev durations`, that is pytest with --write-durations): the longest first.

Fixtures live next to the tests that use them: tests/blender/conftest.py (Blender sessions, the
extension, the tiny room in Blender) and tests/engine/conftest.py (engine runs without bpy).
"""
from __future__ import annotations

import json
from collections import defaultdict
from pathlib import Path

import pytest

#: Each test module's seconds in a whole run of the suite (`./dev durations` writes it).
DURATIONS = Path(__file__).resolve().parent / "durations.json"


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--write-durations", metavar="PATH", type=Path,
                     help="write each test module's seconds (setup, call and teardown summed) to PATH as JSON")


def _skip_setup() -> None:
    """The repository root's setup: nothing (see the module docstring)."""


def pytest_collection_modifyitems(session: pytest.Session, config: pytest.Config, items: list[pytest.Item]) -> None:
    for node in {node for item in items for node in item.listchain()}:
        if isinstance(node, pytest.Package) and node.path == config.rootpath:
            node.setup = _skip_setup
    # `./dev test` hands whole modules to two workers as they come free (pytest-xdist,
    # --dist loadfile): the longest first, or one started last would leave the other worker
    # idle for minutes. Each module's tests stay together and in their order (the sort is stable).
    seconds = _module_seconds(items, config.rootpath, _measured())
    items.sort(key=lambda item: -seconds[item.path])


def _measured() -> dict[str, float]:
    return json.loads(DURATIONS.read_text())["modules"] if DURATIONS.exists() else {}


def _module_seconds(items: list[pytest.Item], root: Path, measured: dict[str, float]) -> dict[Path, float]:
    """Each collected module's expected seconds: its measured ones (`measured`, by path relative to
    `root`). A module not measured yet counts as the longest measured one when it holds a test
    marked slow (it may render minutes), else as 0."""
    slow = {item.path for item in items if item.get_closest_marker("slow")}
    longest = max(measured.values(), default=0.0)
    return {path: measured.get(path.relative_to(root).as_posix(), longest if path in slow else 0.0)
            for path in {item.path for item in items}}


class DurationRecorder:
    """Sums the seconds of every test phase per module and writes them when the session ends
    (on the controller only, under xdist: the workers' reports reach it)."""

    def __init__(self, path: Path) -> None:
        self.path = path
        self.seconds: defaultdict[str, float] = defaultdict(float)

    def pytest_runtest_logreport(self, report: pytest.TestReport) -> None:
        self.seconds[report.nodeid.split("::")[0]] += report.duration

    def pytest_sessionfinish(self, session: pytest.Session) -> None:
        ordered = dict(sorted(((m, round(s, 1)) for m, s in self.seconds.items()), key=lambda kv: -kv[1]))
        self.path.write_text(json.dumps({"modules": ordered}, indent=1) + "\n")


def pytest_configure(config: pytest.Config) -> None:
    path = config.getoption("--write-durations")
    if path is not None and not hasattr(config, "workerinput"):
        config.pluginmanager.register(DurationRecorder(path), "dimred-durations")
