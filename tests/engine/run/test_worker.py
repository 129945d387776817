"""The worker thread: result, error, previews, cancel within a second, and nothing left behind."""
from __future__ import annotations

import gc
import threading
import time
import tracemalloc

import numpy as np
import pytest

from addon.errors import Cancelled, DimredError
from addon.run.worker import Worker


def _wait(worker: Worker, timeout: float = 10.0):
    deadline = time.perf_counter() + timeout
    while time.perf_counter() < deadline:
        update = worker.poll()
        if update.finished:
            return update
        time.sleep(0.005)
    raise AssertionError("the worker did not finish")


def _busy(steps: int = 10_000, preview_every: int = 0):
    """A task like the engine's: numpy steps, progress, a cancel check between steps."""

    def task(callbacks):
        a = np.ones((64, 64))
        for step in range(steps):
            if callbacks.cancel():
                raise Cancelled()
            a = a @ a / 64.0
            callbacks.progress("busy", step / steps)
            if preview_every and step % preview_every == 0:
                callbacks.preview(np.full(3, step))
        return float(a.sum())

    return task


def test_result_arrives_once():
    worker = Worker(lambda callbacks: 42).start()
    update = _wait(worker)
    assert update.result == 42 and update.error is None
    assert worker.join(1.0)
    assert not worker.poll().finished


def test_an_error_reaches_the_main_thread():
    def task(callbacks):
        raise DimredError("bad input")

    update = _wait(Worker(task).start())
    assert isinstance(update.error, DimredError) and str(update.error) == "bad input"


def test_only_the_newest_preview_is_kept():
    shown, release = threading.Event(), threading.Event()

    def task(callbacks):
        for i in range(5):
            callbacks.preview(i)
        shown.set()
        release.wait(5.0)
        return "done"

    worker = Worker(task).start()
    assert shown.wait(5.0)
    # Previews 0-3 were replaced, never queued: a slow main thread gets only the newest.
    assert worker.poll().preview == 4
    assert worker.poll().preview is None
    release.set()
    update = _wait(worker)
    assert update.result == "done" and update.preview is None


def test_preview_arrives_with_progress():
    release = threading.Event()

    def task(callbacks):
        callbacks.progress("stage", 0.25)
        callbacks.preview("coarse")
        callbacks.preview("finer")
        release.wait(5.0)
        return None

    worker = Worker(task).start()
    deadline = time.perf_counter() + 5.0
    seen = None
    while seen is None and time.perf_counter() < deadline:
        seen = worker.poll().preview
        time.sleep(0.002)
    release.set()
    _wait(worker)
    assert seen in ("coarse", "finer")


def test_cancel_stops_within_a_second():
    worker = Worker(_busy(10**9)).start()
    time.sleep(0.05)
    started = time.perf_counter()
    assert worker.stop(timeout=1.0)
    assert time.perf_counter() - started < 1.0
    assert isinstance(worker.poll().error, Cancelled)


def test_a_cancel_after_the_last_check_discards_the_result():
    gate = threading.Event()

    def task(callbacks):
        gate.wait(5.0)
        return "late result"

    worker = Worker(task).start()
    worker.cancel()
    gate.set()
    update = _wait(worker)
    assert update.result is None and isinstance(update.error, Cancelled)


def test_previews_after_cancel_are_dropped():
    def task(callbacks):
        while not callbacks.cancel():
            time.sleep(0.001)
        callbacks.preview("too late")
        raise Cancelled()

    worker = Worker(task).start()
    worker.stop(1.0)
    assert worker.poll().preview is None


@pytest.mark.parametrize("cycles", [100])
def test_many_start_cancel_cycles_leave_no_thread_and_no_memory(cycles):
    before_threads = threading.active_count()

    def cycle():
        worker = Worker(_busy(10**9, preview_every=3)).start()
        time.sleep(0.002)
        assert worker.stop(timeout=1.0)
        worker.poll()

    for _ in range(10):  # warm-up: first allocations of numpy and threading
        cycle()
    gc.collect()
    tracemalloc.start()
    first, _ = tracemalloc.get_traced_memory()
    for _ in range(cycles):
        cycle()
    gc.collect()
    last, _ = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert threading.active_count() == before_threads
    assert last - first < 256 * 1024, f"{last - first} bytes kept after {cycles} cycles"
