"""What the batch must know of a .blend before its jobs run: the panorama's size (for the memory
each job reserves) and the files it reads (for the jobs' fingerprints). `dimred inspect` reads
that in a child process, so a .blend that crashes Blender costs that child, not the batch."""
from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Sequence
from dataclasses import dataclass

from .execute import Launcher


@dataclass(frozen=True)
class Inspection:
    blend: str
    size: tuple[int, int] = (0, 0)  # the panorama's (width, height)
    files: tuple[str, ...] = ()  # the files the scene reads besides the .blend (the panorama)
    error: str = ""  # why the scene cannot be run ("" when it can)


def inspect_scenes(blends: Sequence[str], launcher: Launcher, *, timeout: float = 600.0) -> dict[str, Inspection]:
    """The inspection of every .blend in `blends`. A child that dies on a file leaves that file
    with an error and the rest to a new child."""
    found: dict[str, Inspection] = {}
    left = list(dict.fromkeys(blends))
    while left:
        command, env = launcher.inspect_command(left)
        try:
            proc = subprocess.run(command, env=env, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                                  timeout=timeout)
            stdout, failure = proc.stdout, proc.returncode != 0
        except subprocess.TimeoutExpired as expired:
            stdout, failure = expired.stdout or "", True
            if isinstance(stdout, bytes):
                stdout = stdout.decode("utf-8", "replace")
        for line in stdout.splitlines():
            inspection = _parsed(line)
            if inspection is not None and inspection.blend in left:
                found[inspection.blend] = inspection
        left = [blend for blend in left if blend not in found]
        if left and failure:
            # The first file not reported is the one the child was reading when it died.
            found[left[0]] = Inspection(left[0], error=f"Blender could not read {left[0]} (its process ended while "
                                                       "opening it)")
            left = left[1:]
        elif left:
            for blend in left:
                found[blend] = Inspection(blend, error=f"Blender reported nothing for {blend}")
            left = []
    return found


def _parsed(line: str) -> Inspection | None:
    if not line.startswith('{"blend"'):
        return None
    try:
        record = json.loads(line)
        return Inspection(blend=record["blend"], size=tuple(record.get("size", (0, 0))),
                          files=tuple(record.get("files", ())), error=record.get("error", ""))
    except (ValueError, KeyError, TypeError):
        print(f"dimred batch: cannot read the inspection line {line[:200]!r}", file=sys.stderr)
        return None
