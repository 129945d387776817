"""Cross-correlation of images over every shift, by FFT at lengths that pocketfft transforms
fast: an image's own size can hold a large prime factor (a raster 372 rows high has 31), which
made the transforms of a fill several times slower than a length of small factors."""
from __future__ import annotations

import numpy as np


def fast_length(n: int) -> int:
    """The least length >= n whose prime factors are 2, 3 and 5."""
    best = 1 << (n - 1).bit_length()
    p5 = 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            length = p35
            while length < n:
                length *= 2
            best = min(best, length)
            p35 *= 3
        p5 *= 5
    return best


def correlation_size(a_shape: tuple[int, int], b_shape: tuple[int, int]) -> tuple[int, int]:
    """A transform size at which `correlate` gives every shift of an a_shape image over a
    b_shape one without wrapping (each axis at least the sum of both less one)."""
    return fast_length(a_shape[0] + b_shape[0] - 1), fast_length(a_shape[1] + b_shape[1] - 1)


def spectrum(image: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """The transform of an image (h, w) or (h, w, C) zero-padded to `size`, to correlate."""
    return np.fft.rfft2(image, s=size, axes=(0, 1))


def cross_spectrum(spectrum_a: np.ndarray, spectrum_b: np.ndarray) -> np.ndarray:
    """The spectrum of sum_x a(x) b(x + t), summed over channels: spectra of several
    correlations add up before the one transform back (`correlation`)."""
    product = np.conj(spectrum_a) * spectrum_b
    return product.sum(axis=2) if product.ndim == 3 else product


def correlation(cross: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """The correlation of a `cross_spectrum` for every shift t, indexed by t modulo `size`."""
    return np.fft.irfft2(cross, s=size, axes=(0, 1))
