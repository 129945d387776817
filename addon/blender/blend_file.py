"""Opening a .blend file for the command line, with Blender's own reports kept off stdout.

The command line's output is its own (one line on success, one `dimred: error:` line on bad
input, JSON lines for `inspect`); Blender prints what it reports while loading through Python's
sys.stdout and through C's buffered stdout, so both are captured while a file opens.
"""
from __future__ import annotations

import contextlib
import ctypes
import io
import os
import sys
import tempfile
from collections.abc import Callable, Iterator

from ..errors import DimredError


def open_blend(path: str) -> None:
    """Open a .blend file as the current Blender session; DimredError if it cannot be read."""
    import bpy

    path = os.path.abspath(path)
    if not os.path.isfile(path):
        raise DimredError(f"no such .blend file: {path}")
    with _captured_stdout() as captured:
        try:
            bpy.ops.wm.open_mainfile(filepath=path, load_ui=False)
        except RuntimeError as error:
            reason = str(error).strip().removeprefix("Error:").strip() or captured().strip()
            raise DimredError(f"cannot open {path}: {reason}") from None


@contextlib.contextmanager
def _captured_stdout() -> Iterator[Callable[[], str]]:
    """Keep Blender's own reports off our stdout while loading: Blender prints them through
    Python's sys.stdout and through C's buffered stdout (file descriptor 1)."""
    sys.stdout.flush()
    _flush_c_stdio()
    python_level = io.StringIO()
    with tempfile.TemporaryFile(mode="w+b") as sink:
        saved = os.dup(1)
        os.dup2(sink.fileno(), 1)

        def text() -> str:
            _flush_c_stdio()
            sink.seek(0)
            return sink.read().decode("utf-8", "replace") + python_level.getvalue()

        try:
            with contextlib.redirect_stdout(python_level):
                yield text
        finally:
            _flush_c_stdio()
            os.dup2(saved, 1)
            os.close(saved)


def _flush_c_stdio() -> None:
    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError, TypeError):
        # No C runtime reachable this way (Windows): its output may then reach the terminal.
        pass

