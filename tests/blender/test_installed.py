"""The installed extension end to end on this Blender (5.2): `smoke_installed.py` in a fresh
process, because Blender reads its user folders (where extensions install) once, at start-up."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parent / "smoke_installed.py"


@pytest.mark.slow
def test_installed_extension_removes_renders_and_undoes():
    result = subprocess.run([sys.executable, str(SCRIPT)], capture_output=True, text=True, timeout=600)
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    assert "smoke: 11 passed, 0 failed" in result.stdout
