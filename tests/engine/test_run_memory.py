import ctypes

import numpy as np
import pytest

from addon import run_memory as memory_module
from addon.run_memory import run_memory

multiarray = pytest.importorskip("numpy._core.multiarray")


@pytest.mark.parametrize("before", [True, False])
def test_the_advice_is_off_inside_and_put_back_after(before: bool) -> None:
    previous = multiarray._set_madvise_hugepage(before)
    try:
        with run_memory():
            assert multiarray._get_madvise_hugepage() is False
            np.ones((1024, 1024, 3), dtype=np.float32).sum()
        assert multiarray._get_madvise_hugepage() is before
    finally:
        multiarray._set_madvise_hugepage(previous)


def test_the_advice_is_put_back_when_the_run_fails() -> None:
    previous = multiarray._set_madvise_hugepage(True)
    try:
        with pytest.raises(RuntimeError), run_memory():
            raise RuntimeError("cancelled")
        assert multiarray._get_madvise_hugepage() is True
    finally:
        multiarray._set_madvise_hugepage(previous)


class _Libc:
    def __init__(self) -> None:
        self.calls: list[tuple] = []

    def mallopt(self, parameter: int, value: int) -> int:
        self.calls.append(("mallopt", parameter, value))
        return 1

    def malloc_trim(self, pad: int) -> int:
        self.calls.append(("malloc_trim", pad))
        return 1


def test_malloc_keeps_freed_memory_during_the_run_and_gives_it_back_after(monkeypatch) -> None:
    libc = _Libc()
    monkeypatch.setattr(memory_module, "_glibc", lambda: libc)
    with pytest.raises(RuntimeError), run_memory():
        # and every thread takes its memory from the one heap
        assert libc.calls == [("mallopt", -1, 1 << 30), ("mallopt", -3, 32 << 20), ("mallopt", -8, 1)]
        raise RuntimeError("cancelled")
    assert libc.calls[3:] == [("mallopt", -1, 128 << 10), ("mallopt", -8, 0), ("malloc_trim", 0)]


def test_without_glibc_or_numpy_switch_the_body_runs(monkeypatch) -> None:
    monkeypatch.setattr(memory_module, "_glibc", lambda: None)
    monkeypatch.setattr(memory_module, "_advice_setter", lambda: None)
    ran = []
    with run_memory():
        ran.append(True)
    assert ran == [True]


def test_glibc_is_found_here_when_the_platform_has_it() -> None:
    libc = memory_module._glibc()
    if libc is None:
        pytest.skip("not glibc")
    assert isinstance(libc, ctypes.CDLL)


def test_nested_and_overlapping_runs_share_the_settings_until_the_last_ends(monkeypatch) -> None:
    libc = _Libc()
    monkeypatch.setattr(memory_module, "_glibc", lambda: libc)
    previous = multiarray._set_madvise_hugepage(True)
    try:
        outer = run_memory()
        outer.__enter__()
        with run_memory():  # the pipeline's inside the command line's
            assert len(libc.calls) == 3 and multiarray._get_madvise_hugepage() is False
        assert len(libc.calls) == 3 and multiarray._get_madvise_hugepage() is False
        second = run_memory()  # another thread's, begun before the first ends
        second.__enter__()
        outer.__exit__(None, None, None)
        assert len(libc.calls) == 3 and multiarray._get_madvise_hugepage() is False
        second.__exit__(None, None, None)
        assert libc.calls[3:] == [("mallopt", -1, 128 << 10), ("mallopt", -8, 0), ("malloc_trim", 0)]
        assert multiarray._get_madvise_hugepage() is True
    finally:
        multiarray._set_madvise_hugepage(previous)
