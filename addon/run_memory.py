"""How a removal's large arrays get their memory: pages mapped once and used again, not
mapped afresh for every band.

A run allocates arrays the panorama's size, and band after band arrays of megabytes, and
frees them as it goes. Two defaults of Linux make each of those allocations cost a fresh
mapping, whose every page the kernel hands over at its first touch:
- numpy advises the kernel to back each array of 4 MB or more with transparent huge pages;
  where the kernel answers by compacting memory on the spot (`defrag` set to `madvise`, the
  default of common distributions), the first touch waits for it. A sum of two 8192 x 4096
  panoramas into a new array took 2.0 s with the advice, 0.18 s without.
- glibc's malloc gives the top of its heap back to the system once 128 kB or more is free
  there (the threshold grows to twice the largest block seen), and maps blocks of 32 MB or
  more on their own.
At 8192 x 4096 a balanced removal took 36.6 s with 11.1 s in the kernel; without the advice
25.2 s; with malloc keeping up to 1 GB of freed memory for the next band as well, the
engine's 1.2 M page faults became 0.45 M (4.2 -> 2.9 s in the kernel). So the run turns the
advice off and lets malloc keep what it frees; when it ends it puts the advice back and
hands the kept memory back to the system (Blender's process lives on after the run).

Stages that run on two threads would each get an arena of malloc's own, whose memory is
mapped and handed back apart from the main heap's: with them, the 8K removal whose upsampling
runs on two threads spent 1.7-2.9 s in the kernel instead of 0.7 s. During a run every thread
takes its memory from the one heap (0.7 s again).
"""
from __future__ import annotations

import ctypes
import importlib
import sys
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager

# glibc's mallopt parameters (malloc.h) and the values the run sets.
_M_TRIM_THRESHOLD = -1
_M_MMAP_THRESHOLD = -3
_M_ARENA_MAX = -8
_KEPT_BYTES = 1 << 30  # freed memory malloc keeps at its heap's top during a run
_OWN_MAPPING_BYTES = 32 << 20  # glibc's largest: smaller blocks come from the heap
_DEFAULT_TRIM_BYTES = 128 << 10  # glibc's default, put back after the run
_DEFAULT_ARENAS = 0  # glibc's default: as many arenas as it sees fit


def _advice_setter() -> Callable[[bool], bool] | None:
    """numpy's switch of the huge-page advice (it returns the previous setting), or None
    where this numpy has none."""
    for name in ("numpy._core.multiarray", "numpy.core.multiarray"):
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        setter = getattr(module, "_set_madvise_hugepage", None)
        if setter is not None:
            return setter
    return None


def _glibc() -> ctypes.CDLL | None:
    """The C library where it is glibc (its mallopt and malloc_trim), else None."""
    if not sys.platform.startswith("linux"):
        return None
    try:
        libc = ctypes.CDLL(None)
        libc.gnu_get_libc_version  # noqa: B018 - glibc only: musl has no mallopt
        libc.mallopt, libc.malloc_trim  # noqa: B018
    except (OSError, AttributeError):
        return None
    return libc


class _Held:
    """The runs inside `run_memory` now (the command line's around the pipeline's, the add-on's
    job beside a script's) and the huge-page advice the first of them found: the settings are
    the process's, so the first run in sets them and the last one out puts them back."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.runs = 0
        self.advice: bool | None = None


_HELD = _Held()


@contextmanager
def run_memory() -> Iterator[None]:
    """Run the body with numpy's huge-page advice off and glibc's malloc keeping freed memory;
    afterwards put the advice back and give the memory kept to the system. Nested and
    concurrent runs share the settings until the last of them ends."""
    setter, libc = _advice_setter(), _glibc()
    with _HELD.lock:
        _HELD.runs += 1
        if _HELD.runs == 1:
            _HELD.advice = setter(False) if setter is not None else None
            if libc is not None:
                libc.mallopt(_M_TRIM_THRESHOLD, _KEPT_BYTES)
                libc.mallopt(_M_MMAP_THRESHOLD, _OWN_MAPPING_BYTES)
                libc.mallopt(_M_ARENA_MAX, 1)
    try:
        yield
    finally:
        with _HELD.lock:
            _HELD.runs -= 1
            if _HELD.runs == 0:
                if setter is not None:
                    setter(_HELD.advice)
                if libc is not None:
                    libc.mallopt(_M_TRIM_THRESHOLD, _DEFAULT_TRIM_BYTES)
                    libc.mallopt(_M_ARENA_MAX, _DEFAULT_ARENAS)
                    libc.malloc_trim(0)
