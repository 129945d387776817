"""The local light's exact shadows computed on two threads give what one thread gives."""
from __future__ import annotations

import numpy as np

from addon.removal import local


def test_pairs_split_between_two_threads_keep_each_points_pairs_together_and_their_values():
    rng = np.random.default_rng(2)
    pix = rng.integers(0, 5000, local._THREADED_PAIRS + 1000)
    senders = rng.integers(0, 30, len(pix))
    calls: list[np.ndarray] = []

    def shadow(p: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        calls.append(p)
        # a value that depends on the point's other pairs, as its emitters' shared rays do
        per_point = np.bincount(p, s, minlength=5000)[p]
        value = np.stack([p * 1.0, s * 1.0, per_point], axis=1)
        return value, -value

    e, de = local._on_two_threads(shadow)(pix, senders)
    assert len(calls) == 2 and not np.intersect1d(calls[0], calls[1]).size
    calls.clear()
    e_one, de_one = shadow(pix, senders)
    np.testing.assert_array_equal(e, e_one)
    np.testing.assert_array_equal(de, de_one)


def test_few_pairs_stay_on_one_thread():
    calls = []

    def shadow(p, s):
        calls.append(len(p))
        return np.zeros((len(p), 3)), np.zeros((len(p), 3))

    local._on_two_threads(shadow)(np.arange(100), np.zeros(100, dtype=np.int64))
    assert calls == [100]
