import numpy as np
import pytest

from addon import page_advice
from addon.page_advice import without_huge_page_advice

multiarray = pytest.importorskip("numpy._core.multiarray")


@pytest.mark.parametrize("before", [True, False])
def test_advice_is_off_inside_and_restored_after(before: bool) -> None:
    previous = multiarray._set_madvise_hugepage(before)
    try:
        with without_huge_page_advice():
            assert multiarray._get_madvise_hugepage() is False
            np.ones((1024, 1024, 3), dtype=np.float32).sum()
        assert multiarray._get_madvise_hugepage() is before
    finally:
        multiarray._set_madvise_hugepage(previous)


def test_advice_is_restored_when_the_run_fails() -> None:
    previous = multiarray._set_madvise_hugepage(True)
    try:
        with pytest.raises(RuntimeError), without_huge_page_advice():
            raise RuntimeError("cancelled")
        assert multiarray._get_madvise_hugepage() is True
    finally:
        multiarray._set_madvise_hugepage(previous)


def test_a_numpy_without_the_switch_runs_the_body(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(page_advice, "_setter", lambda: None)
    ran = []
    with without_huge_page_advice():
        ran.append(True)
    assert ran == [True]
