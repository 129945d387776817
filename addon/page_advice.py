"""Numpy's huge-page advice, turned off while a removal runs.

On Linux numpy asks the kernel for transparent huge pages for every array of 4 MB or more.
Where the kernel answers that advice by compacting memory on the spot (`defrag` set to
`madvise`, the default of common distributions), each first touch of a new array can wait for
it: at 8192 x 4096 a removal spent 11 s of its 37 in the kernel, 2 s without the advice, and a
sum of two panoramas into a new array took 2.0 s against 0.18 s. The run allocates arrays the
panorama's size band after band, so it runs without the advice; the kernel still hands out
huge pages where it has them free (`enabled` set to `always`). The advice is numpy's
process-wide setting, so it is restored when the run ends.
"""
from __future__ import annotations

import importlib
from collections.abc import Callable, Iterator
from contextlib import contextmanager


def _setter() -> Callable[[bool], bool] | None:
    """numpy's switch of the advice (it returns the previous setting), or None where this
    numpy has none (not Linux builds, or a version that dropped it)."""
    for name in ("numpy._core.multiarray", "numpy.core.multiarray"):
        try:
            module = importlib.import_module(name)
        except ImportError:
            continue
        setter = getattr(module, "_set_madvise_hugepage", None)
        if setter is not None:
            return setter
    return None


@contextmanager
def without_huge_page_advice() -> Iterator[None]:
    """Run the body with numpy's huge-page advice off, and put the earlier setting back."""
    setter = _setter()
    if setter is None:
        yield
        return
    before = setter(False)
    try:
        yield
    finally:
        setter(before)
