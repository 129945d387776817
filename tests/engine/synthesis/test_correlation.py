"""FFT correlation at fast lengths, checked against sums over shifts written out."""
from __future__ import annotations

import numpy as np

from addon.synthesis.correlation import correlation, correlation_size, cross_spectrum, fast_length, spectrum


def _small_factors_only(n: int) -> bool:
    for p in (2, 3, 5):
        while n % p == 0:
            n //= p
    return n == 1


def test_fast_length_is_the_least_length_of_small_factors():
    for n in range(1, 2000):
        length = fast_length(n)
        assert length >= n and _small_factors_only(length)
        assert not any(_small_factors_only(k) for k in range(n, length))


def test_correlation_gives_every_shift_without_wrapping():
    rng = np.random.default_rng(3)
    a, b = rng.random((7, 31, 2)), rng.random((11, 13, 2))
    size = correlation_size(a.shape[:2], b.shape[:2])
    c = correlation(cross_spectrum(spectrum(a, size), spectrum(b, size)), size)
    for ty in range(-6, 11):
        for tx in range(-30, 13):
            direct = sum(a[y, x] @ b[y + ty, x + tx] for y in range(7) for x in range(31)
                         if 0 <= y + ty < 11 and 0 <= x + tx < 13)
            assert abs(c[ty % size[0], tx % size[1]] - direct) < 1e-9
