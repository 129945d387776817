"""Fixtures of the batch's tests: the Blender stand-in (`standin`) and a folder of scenes."""
from __future__ import annotations

import sys
from pathlib import Path

import pytest

from addon.batch.execute import Launcher
from tests.engine.batch.standin import fake_launcher


@pytest.fixture
def fake_blender(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Launcher:
    """A Launcher whose 'Blender' is the stand-in; its calls are logged to tmp_path/calls.jsonl."""
    if sys.platform == "win32":
        pytest.skip("the stand-in is a script run through its #! line")
    monkeypatch.setenv("FAKE_DIMRED_LOG", str(tmp_path / "calls.jsonl"))
    return fake_launcher(tmp_path)


@pytest.fixture
def scenes(tmp_path: Path) -> Path:
    """A folder of small .blend stand-ins (any bytes do: the stand-in only copies them), each
    with its panorama file beside it."""
    folder = tmp_path / "scenes"
    folder.mkdir()
    for name in ("kitchen", "bedroom", "hall"):
        (folder / f"{name}.blend").write_bytes(f"BLENDER {name}".encode())
        (folder / f"{name}.blend.exr").write_bytes(f"panorama of {name}".encode())
    return folder
