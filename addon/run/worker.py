"""A background thread for one engine run, with progress, previews, cancel and a clean join.

Blender's data must only be touched on the main thread, so the worker runs a plain function
on plain arrays and the main thread polls it (a modal operator's timer): `poll()` hands back
the latest progress, the latest preview and, once, the result or the error. Only the newest
preview is kept, so a slow main thread never piles up images.
"""
from __future__ import annotations

import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from ..callbacks import RunCallbacks
from ..errors import Cancelled

T = TypeVar("T")
Task = Callable[[RunCallbacks], T]


@dataclass
class Update(Generic[T]):
    """What happened since the last poll."""

    stage: str
    fraction: float
    preview: Any | None = None  # the newest preview, if one arrived since the last poll
    finished: bool = False  # the task ended: `result` or `error` is set (an error on cancel)
    result: T | None = None
    error: BaseException | None = None


class Worker(Generic[T]):
    """Runs `task(callbacks)` in a daemon thread.

    The task reports with `callbacks.progress(stage, fraction)` and `callbacks.preview(obj)` and
    should call `callbacks.check()` often (the engine does between steps), which raises
    `Cancelled` once the worker is cancelled.
    """

    def __init__(self, task: Task, name: str = "dimred-worker") -> None:
        self._task = task
        self._lock = threading.Lock()
        self._cancel = threading.Event()
        self._stage, self._fraction = "starting", 0.0
        self._preview: Any | None = None
        self._outcome: tuple[T | None, BaseException | None] | None = None
        self._delivered = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)

    def start(self) -> Worker[T]:
        self._thread.start()
        return self

    def cancel(self) -> None:
        """Ask the task to stop; it raises `Cancelled` at its next check."""
        self._cancel.set()

    @property
    def cancelled(self) -> bool:
        return self._cancel.is_set()

    def join(self, timeout: float | None = None) -> bool:
        """Wait for the thread; True when it has ended."""
        if self._thread.ident is not None:
            self._thread.join(timeout)
        return not self._thread.is_alive()

    def stop(self, timeout: float = 5.0) -> bool:
        """Cancel and join: what file load, unregister and exit call. True when it has ended."""
        self.cancel()
        return self.join(timeout)

    def poll(self) -> Update[T]:
        """Progress so far; `finished` is True exactly once, in the first poll after the end."""
        with self._lock:
            update: Update[T] = Update(self._stage, self._fraction, self._preview)
            self._preview = None
            if self._outcome is not None and not self._delivered:
                self._delivered = True
                update.finished = True
                update.result, update.error = self._outcome
                # The caller owns the result now; the worker keeps no reference to large arrays.
                self._outcome = (None, None)
        return update

    def _progress(self, stage: str, fraction: float) -> None:
        with self._lock:
            self._stage, self._fraction = stage, float(fraction)

    def _show(self, preview: Any) -> None:
        if self._cancel.is_set():
            return
        with self._lock:
            self._preview = preview

    def _run(self) -> None:
        result: T | None = None
        error: BaseException | None = None
        try:
            result = self._task(RunCallbacks(self._progress, self._cancel.is_set, self._show))
            if self._cancel.is_set():
                # Cancelled after the last check: the result must not be applied.
                raise Cancelled()
        except BaseException as exc:
            result, error = None, exc
        with self._lock:
            self._preview = None
            self._outcome = (result, error)
