"""Gaussian mixture models of colour in log radiance, one for the object and one for its
surroundings.

In log radiance a shadow on the floor shifts the floor's colour rather than scaling it, and a
lamp 1e4 times brighter lies a few units away rather than four orders of magnitude, so that a
few Gaussians describe an HDR window.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_LUMINANCE = np.array([0.2126, 0.7152, 0.0722], dtype=np.float32)
_LOG_2PI = float(np.log(2.0 * np.pi))
# Log density (per unit log radiance cubed) of colours neither mixture explains, about 5.6 sigma
# from a typical component: a pixel far from both models (a lamp the subsample missed) then
# costs the same under both, and the prior and the smoothness rather than the Gaussians' tails
# decide its side.
_OUTLIER_LOG_DENSITY = -14.0
_MIN_VARIANCE = 1e-3  # floor on each component's variance (log units^2): about 3 % in radiance


@dataclass(frozen=True)
class ColourModel:
    """A mixture of k Gaussians over 3-channel log radiance."""

    weights: np.ndarray  # (k,) float64, summing to 1
    means: np.ndarray  # (k, 3) float64
    covariances: np.ndarray  # (k, 3, 3) float64

    def log_likelihood(self, features: np.ndarray) -> np.ndarray:
        """(N,) float32 log density of features (N, 3), the outlier floor mixed in."""
        x = np.asarray(features, dtype=np.float64)
        per = _component_log_densities(x, self.weights, self.means, self.covariances)
        per = np.concatenate([per, np.full((len(x), 1), _OUTLIER_LOG_DENSITY)], axis=1)
        return _log_sum_exp(per).astype(np.float32)


def log_features(image: np.ndarray, *, floor: float = 0.01) -> np.ndarray:
    """(h, w, 3) float32 log(radiance + eps) of a window (h, w, 3); eps is `floor` times the
    window's median luminance, so that black and noisy-dark pixels do not spread to -inf."""
    rgb = np.maximum(np.asarray(image, dtype=np.float32), 0.0)
    median = float(np.median(rgb @ _LUMINANCE))
    eps = floor * median if median > 0.0 else 1e-6
    return np.log(rgb + np.float32(eps))


def fit_colour_model(samples: np.ndarray, *, components: int = 5, em_steps: int = 4, max_samples: int = 2000,
                     seed: int = 0) -> ColourModel:
    """The mixture fitted to samples (N, 3), N >= 1: k-means++ seeds, then `em_steps` rounds of
    expectation-maximisation, on a seeded subsample of at most `max_samples`."""
    rng = np.random.default_rng(seed)
    x = np.asarray(samples, dtype=np.float64).reshape(-1, 3)
    if not len(x):
        raise ValueError("a colour model needs at least one sample")
    if len(x) > max_samples:
        x = x[np.sort(rng.choice(len(x), max_samples, replace=False))]
    centres = _seeds(x, min(components, len(x)), rng)
    nearest = np.argmin(((x[:, None, :] - centres[None]) ** 2).sum(-1), axis=1)
    resp = np.zeros((len(x), len(centres)))
    resp[np.arange(len(x)), nearest] = 1.0
    weights, means, covariances = _maximise(x, resp)
    for _ in range(em_steps):
        per = _component_log_densities(x, weights, means, covariances)
        resp = np.exp(per - _log_sum_exp(per)[:, None])
        weights, means, covariances = _maximise(x, resp)
    return ColourModel(weights=weights, means=means, covariances=covariances)


def _seeds(x: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
    """k-means++: each further centre drawn with probability proportional to the squared distance
    to the nearest centre so far."""
    centres = [x[rng.integers(len(x))]]
    d2 = ((x - centres[0]) ** 2).sum(-1)
    for _ in range(k - 1):
        total = d2.sum()
        if total <= 0.0:
            break  # every sample equals a centre: more components would be empty
        centres.append(x[rng.choice(len(x), p=d2 / total)])
        d2 = np.minimum(d2, ((x - centres[-1]) ** 2).sum(-1))
    return np.array(centres)


def _maximise(x: np.ndarray, resp: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weights, means and covariances from responsibilities (N, k); components that hold less
    than one sample are dropped."""
    mass = resp.sum(0)
    keep = mass >= 1.0
    resp, mass = resp[:, keep], mass[keep]
    means = (resp.T @ x) / mass[:, None]
    diff = x[None] - means[:, None, :]  # (k, N, 3)
    covariances = (resp.T[:, :, None] * diff).transpose(0, 2, 1) @ diff / mass[:, None, None]
    covariances += _MIN_VARIANCE * np.eye(3)
    return mass / mass.sum(), means, covariances


def _component_log_densities(x: np.ndarray, weights: np.ndarray, means: np.ndarray,
                             covariances: np.ndarray) -> np.ndarray:
    """(N, k) log(weight_k N(x | mean_k, cov_k)).

    Each component's exponent is a quadratic polynomial in x, so all of them come from one
    (N, 10) x (10, k) product of x's monomials with the polynomials' coefficients, far faster
    than whitening N points per component with 3 x 3 products.
    """
    precision = np.linalg.inv(covariances)  # (k, 3, 3)
    log_det = np.linalg.slogdet(covariances)[1]
    pm = np.einsum("kij,kj->ki", precision, means)
    i, j = np.triu_indices(3, 1)
    coefficients = np.concatenate([
        -0.5 * np.diagonal(precision, axis1=1, axis2=2),  # x_i^2
        -precision[:, i, j],  # x_i x_j, i < j (each appears twice in the quadratic form)
        pm,  # x_i
        (np.log(weights) - 0.5 * ((pm * means).sum(-1) + log_det + 3.0 * _LOG_2PI))[:, None],
    ], axis=1)  # (k, 10)
    monomials = np.concatenate([x * x, x[:, i] * x[:, j], x, np.ones((len(x), 1))], axis=1)
    return monomials @ coefficients.T


def _log_sum_exp(a: np.ndarray) -> np.ndarray:
    top = a.max(axis=1)
    return top + np.log(np.exp(a - top[:, None]).sum(axis=1))
