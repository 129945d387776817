"""Work on two threads: results in order, exceptions raised, one item on the caller's thread."""
from __future__ import annotations

import threading
import time

import pytest

from addon.side_by_side import THREADS, both, each


def test_both_gives_both_results_and_runs_the_second_elsewhere_meanwhile():
    started = threading.Event()

    def there():
        started.set()
        return threading.get_ident()

    def here():
        assert started.wait(5), "the second did not start while the first ran"
        return threading.get_ident()

    mine, theirs = both(here, there)
    assert mine == threading.get_ident() and theirs != mine


def test_both_raises_what_either_raised():
    with pytest.raises(KeyError):
        both(lambda: 1, lambda: {}["missing"])
    with pytest.raises(ZeroDivisionError):
        both(lambda: 1 / 0, lambda: 2)


def test_each_keeps_the_items_order_whatever_order_they_end_in():
    def slower_first(k):
        time.sleep(0.02 * (4 - k))
        return k * k, threading.get_ident()

    results = each(slower_first, range(4))
    assert [value for value, _ in results] == [0, 1, 4, 9]
    assert len({thread for _, thread in results}) == THREADS


def test_each_runs_a_single_item_on_the_callers_thread():
    assert each(lambda _: threading.get_ident(), [0]) == [threading.get_ident()]
    assert each(lambda x: x, []) == []
