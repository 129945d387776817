"""Gaussian mixtures of log colour: fitted to clusters they find them, score their own colours
above others, stay finite for any input, and repeat themselves for a seed."""
from __future__ import annotations

import numpy as np

from addon.segmentation.colour_model import fit_colour_model, log_features


def _clusters(seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    centres = np.array([[0.0, 0.0, 0.0], [3.0, -1.0, 2.0]])
    sizes = (3000, 1000)
    samples = np.concatenate([c + 0.2 * rng.standard_normal((n, 3)) for c, n in zip(centres, sizes, strict=True)])
    return samples, centres


def test_log_features_make_a_shadow_a_shift_and_stay_finite_at_black():
    rng = np.random.default_rng(0)
    lit = 0.3 + 0.05 * rng.random((10, 10, 3))
    image = np.concatenate([lit, 0.25 * lit], axis=1).astype(np.float32)
    image[0, 0] = 0.0
    f = log_features(image)
    assert np.all(np.isfinite(f))
    # eps is 1 % of the median luminance: the shadow (a quarter of the light) is a near-constant shift.
    shift = f[1:, :10] - f[1:, 10:]
    assert np.all(np.abs(shift - np.log(4.0)) < 0.05)


def test_fit_finds_the_clusters_and_their_shares():
    samples, centres = _clusters()
    model = fit_colour_model(samples, components=2, em_steps=8)
    order = np.argsort(model.means[:, 0])
    assert np.allclose(model.means[order], centres, atol=0.05)
    assert np.allclose(model.weights[order], [0.75, 0.25], atol=0.03)
    assert np.allclose(model.covariances[order[0]], 0.04 * np.eye(3), atol=0.01)


def test_likelihood_is_higher_for_the_model_s_own_colours_and_floored_far_away():
    samples, centres = _clusters()
    model = fit_colour_model(samples)
    far = np.array([[20.0, 20.0, 20.0], [60.0, -60.0, 0.0]])
    ll = model.log_likelihood(np.concatenate([centres, far]))
    assert ll.dtype == np.float32
    assert ll[:2].min() > ll[2:].max() + 10.0
    # Colours no component explains share one floor, whatever their distance.
    assert abs(ll[2] - ll[3]) < 1e-3


def test_fit_is_deterministic_for_a_seed_and_subsamples_large_sets():
    samples, _ = _clusters()
    a = fit_colour_model(samples, seed=3, max_samples=500)
    b = fit_colour_model(samples, seed=3, max_samples=500)
    assert np.array_equal(a.means, b.means) and np.array_equal(a.covariances, b.covariances)
    c = fit_colour_model(samples, seed=4, max_samples=500)
    assert not np.array_equal(a.means, c.means)


def test_fit_copes_with_fewer_distinct_samples_than_components():
    one = fit_colour_model(np.array([[1.0, 2.0, 3.0]]))
    assert len(one.weights) == 1 and np.all(np.isfinite(one.log_likelihood(np.zeros((2, 3)))))
    same = fit_colour_model(np.tile([0.5, 0.5, 0.5], (40, 1)))
    assert len(same.weights) == 1
    assert np.isfinite(np.linalg.slogdet(same.covariances)[1]).all()
