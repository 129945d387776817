"""The run report: seconds per stage, skipped stages with reasons, warnings and guards.

It is written as report.json next to the images and shown in Blender's panel.
"""
from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager


class Report:
    """Collects what a run did; `as_dict()` is JSON-serialisable."""

    def __init__(self, progress: Callable[[str, float], None] | None = None, *, stages: int = 1) -> None:
        self.seconds: dict[str, float] = {}
        self.skipped: dict[str, str] = {}
        self.warnings: list[str] = []
        self.guards: dict[str, int] = {}
        self.info: dict[str, object] = {}
        self._progress = progress
        self._stages = max(stages, 1)
        self._start = time.perf_counter()
        self._lock = threading.Lock()  # a stage's threads may count guards at once

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        if self._progress is not None:
            self._progress(name, min(len(self.seconds) / self._stages, 1.0))
        t0 = time.perf_counter()
        try:
            yield
        finally:
            self.seconds[name] = self.seconds.get(name, 0.0) + time.perf_counter() - t0

    def skip(self, name: str, reason: str) -> None:
        self.skipped[name] = reason

    def warn(self, message: str) -> None:
        self.warnings.append(message)

    def guard(self, name: str, count: int) -> None:
        with self._lock:
            self.guards[name] = self.guards.get(name, 0) + int(count)

    def as_dict(self) -> dict:
        seconds = {k: round(v, 4) for k, v in self.seconds.items()}
        seconds["total"] = round(time.perf_counter() - self._start, 4)
        return {
            "seconds": seconds,
            "skipped": [{"stage": k, "reason": v} for k, v in self.skipped.items()],
            "warnings": list(self.warnings),
            "guards": dict(self.guards),
            **self.info,
        }
