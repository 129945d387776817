"""Work done on two threads: numpy lets go of the interpreter lock for its arithmetic on large
arrays, so two pieces of a stage that read what they share and write only what is their own
take the time of the longer on two cores (on one, about the time of both, as before).

Two, not a thread per core: the stages split their work in halves or in bands, and the arrays
in flight per thread are a band's; with more, the run's peak memory would grow with the
machine. During a run every thread takes its memory from malloc's one heap (`run_memory`).
"""
from __future__ import annotations

from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor
from typing import TypeVar

_A = TypeVar("_A")
_B = TypeVar("_B")
_T = TypeVar("_T")

THREADS = 2


def both(here: Callable[[], _A], there: Callable[[], _B]) -> tuple[_A, _B]:
    """(here(), there()), `there` computed on a second thread meanwhile. An exception from
    either (a cancelled run's) is raised once both have ended."""
    with ThreadPoolExecutor(max_workers=1) as pool:
        pending = pool.submit(there)
        return here(), pending.result()


def each(work: Callable[[_T], _A], items: Iterable[_T]) -> list[_A]:
    """[work(item) for item in items], THREADS items at a time, in the items' order; on this
    thread alone when there is one item or none."""
    items = list(items)
    if len(items) < 2:
        return [work(item) for item in items]
    with ThreadPoolExecutor(max_workers=THREADS) as pool:
        return list(pool.map(work, items))
