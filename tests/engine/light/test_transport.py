"""Visibility of senders from points, with the removed object and without it."""
from __future__ import annotations

import numpy as np

from addon.geometry.occluders import Occluders
from addon.geometry.patches import triangle_samples
from addon.light.transport import make_senders, pair_visibility, spread_order


def _lamp_half_hidden():
    """A lamp 2 m above a point on the floor, a board in between covering the lamp's half x < 0."""
    lamp = np.array([[[-1.0, -1, 2], [1, -1, 2], [0, 1.5, 2]]])
    senders = make_senders(lamp, np.array([[0.0, 0, -1]]), np.ones((1, 3)), np.zeros(1, dtype=bool),
                           [(np.arange(1), triangle_samples(lamp, 4))])
    board = np.array([[[-3.0, -3, 1], [0, -3, 1], [0, 3, 1]], [[-3.0, -3, 1], [0, 3, 1], [-3, 3, 1]]])
    return senders, Occluders(board, np.zeros(2, dtype=np.int64), 1e-6)


def test_a_removed_board_hides_part_of_the_lamp_and_nothing_without_it():
    senders, board = _lamp_half_hidden()
    vis, vis_without = pair_visibility(np.zeros((1, 3)), senders, np.zeros(1, dtype=np.int64),
                                       np.zeros(1, dtype=np.int64), board, None)
    assert 0.2 < vis[0] < 0.8 and vis_without[0] == 1.0


def test_a_pair_given_fewer_samples_takes_the_first_of_a_spread_order():
    senders, board = _lamp_half_hidden()
    r, s = np.zeros(3, dtype=np.int64), np.zeros(3, dtype=np.int64)
    vis, _ = pair_visibility(np.zeros((1, 3)), senders, r, s, board, None, counts=np.array([16, 4, 1]))
    whole, _ = pair_visibility(np.zeros((1, 3)), senders, r[:1], s[:1], board, None)
    assert vis[0] == whole[0]
    assert vis[2] in (0.0, 1.0) and 0.0 <= vis[1] <= 1.0
    # The first four samples of the order reach both halves of the lamp.
    assert 0.0 < vis[1] < 1.0


def test_the_spread_order_is_a_permutation_whose_prefixes_spread():
    samples = triangle_samples(np.array([[[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]]), 4)[0]
    order = spread_order(samples)
    assert sorted(order.tolist()) == list(range(16))
    first = samples[order[:4]]
    assert np.linalg.norm(first[:, None] - first[None], axis=2)[np.triu_indices(4, 1)].min() > 0.2
