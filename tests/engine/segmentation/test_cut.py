"""The relaxed graph cut thresholds to the exact minimum of the binary energy (checked by trying
every labelling of a small window), folds fixed pixels into the data term, and its contrast
weights follow the image's edges."""
from __future__ import annotations

import itertools

import numpy as np

from addon.segmentation.cut import contrast_beta, contrast_graph, labelled, relax


def _energies(graph, data: np.ndarray, labellings: np.ndarray) -> np.ndarray:
    """The binary energy (up to a constant) of each row of labellings (k, n)."""
    x = labellings.astype(np.float64)
    return x @ (data + graph.pull) + np.abs(x[:, graph.first] - x[:, graph.second]) @ graph.weight


def test_thresholded_relaxation_is_the_exact_minimum_of_random_energies():
    rng = np.random.default_rng(0)
    free = np.zeros((6, 7), dtype=bool)
    free[1:5, 1:5] = True  # 16 free pixels: 65536 labellings
    every = np.array(list(itertools.product((0, 1), repeat=16)), dtype=bool)
    for trial in range(6):
        features = rng.standard_normal((6, 7, 3)).astype(np.float32)
        fixed = rng.random((6, 7)) < 0.5
        graph = contrast_graph(features, free, fixed, smoothness=1.5, beta=0.3)
        data = (2.0 * rng.standard_normal(16)).astype(np.float32)
        best = _energies(graph, data, every).min()
        got = _energies(graph, data, relax(graph, data, iterations=600).labels[None])[0]
        assert got <= best + 1e-3, trial


def test_fixed_neighbours_pull_a_doubtful_pixel_to_their_side():
    features = np.zeros((5, 5, 3), dtype=np.float32)
    free = np.zeros((5, 5), dtype=bool)
    free[2, 2] = True
    for side in (False, True):
        fixed = np.full((5, 5), side)
        graph = contrast_graph(features, free, fixed, smoothness=1.0, beta=0.0)
        assert graph.pull[0] == (-1.0 if side else 1.0) * (4 + 4 * 2 ** -0.5)
        # A data term favouring the other side by less than the neighbours' pull loses.
        doubt = np.array([3.0 if side else -3.0], dtype=np.float32)
        assert relax(graph, doubt, iterations=200).labels[0] == side


def test_weights_drop_across_an_edge_and_beta_is_grabcut_s():
    features = np.zeros((8, 8, 3), dtype=np.float32)
    features[:, 4:] = 1.0
    region = np.ones((8, 8), dtype=bool)
    beta = contrast_beta(features, region)
    # 8 x 8 pixels: 56 + 56 + 49 + 49 pairs; the edge crosses 8 horizontal and 14 diagonal pairs
    # of squared difference 3.
    assert np.isclose(beta, 0.5 * 210 / (3 * 22))
    graph = contrast_graph(features, region, np.zeros((8, 8), dtype=bool), smoothness=2.0, beta=beta)
    col = graph.free % 8
    across = (col[graph.first] < 4) != (col[graph.second] < 4)
    length = np.where(np.isin(np.abs(graph.first - graph.second), (1, 8)), 1.0, 2 ** -0.5)
    assert np.allclose(graph.weight, 2.0 * length * np.where(across, np.exp(-3.0 * beta), 1.0))


def test_a_warm_start_that_is_already_optimal_stays():
    features = np.zeros((10, 10, 3), dtype=np.float32)
    free = np.ones((10, 10), dtype=bool)
    truth = np.zeros((10, 10), dtype=bool)
    truth[3:7, 3:7] = True
    graph = contrast_graph(features, free, np.zeros((10, 10), dtype=bool), smoothness=0.5, beta=0.0)
    data = np.where(truth.ravel(), -5.0, 5.0).astype(np.float32)
    state = relax(graph, data, iterations=300, start=labelled(graph, truth.ravel()))
    assert np.array_equal(state.labels, truth.ravel())
