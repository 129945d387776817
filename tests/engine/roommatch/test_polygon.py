"""The floor polygon's checks: a crossing found, a fold back along an edge found, orientation,
containment and the ray to the nearest wall."""
from __future__ import annotations

import numpy as np
import pytest

from addon.roommatch.polygon import contains, crossing_edges, ray_hit, signed_area

SQUARE = np.array([(0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)])


def test_a_simple_polygon_has_no_crossing() -> None:
    assert crossing_edges(SQUARE) is None
    assert crossing_edges(np.array([(0, 0), (3, 0), (3, 1), (1, 1), (1, 3), (0, 3)], dtype=float)) is None


def test_a_bow_tie_crosses() -> None:
    assert crossing_edges(SQUARE[[0, 2, 1, 3]]) == (0, 2)


def test_an_edge_folding_back_counts_as_crossing() -> None:
    assert crossing_edges(np.array([(0, 0), (2, 0), (1, 0), (1, 2)], dtype=float)) is not None


def test_orientation_and_containment() -> None:
    assert signed_area(SQUARE) == pytest.approx(4.0)
    assert signed_area(SQUARE[::-1]) == pytest.approx(-4.0)
    assert contains(SQUARE, np.array([1.0, 1.0])) and not contains(SQUARE, np.array([3.0, 1.0]))


def test_the_ray_meets_the_nearest_wall() -> None:
    centred = SQUARE - 1.0
    assert ray_hit(centred, np.array([1.0, 0.0])) == pytest.approx(1.0)
    assert ray_hit(centred, np.array([1.0, 1.0]) / np.sqrt(2)) == pytest.approx(np.sqrt(2))
    assert ray_hit(SQUARE + 5.0, np.array([-1.0, 0.0])) is None  # the polygon lies behind the ray
