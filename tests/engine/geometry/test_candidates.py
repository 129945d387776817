"""First hits among candidate triangles, and rasterising a window of the panorama, against
rasterising the whole panorama."""
from __future__ import annotations

import numpy as np
import pytest

from addon.geometry.candidates import hits_among
from addon.geometry.raycast import trace_panorama


@pytest.fixture(scope="module")
def triangles() -> np.ndarray:
    rng = np.random.default_rng(3)
    near = rng.normal(size=(80, 3, 3)) * 0.4 + np.array([1.0, 0.3, -0.2])
    far = rng.normal(size=(30, 3, 3)) * 2.0
    return np.concatenate([near, far])


def test_every_triangle_as_a_candidate_finds_what_the_rasteriser_finds(triangles):
    full = trace_panorama(triangles, 96, 48)
    dirs = full.directions.reshape(-1, 3)
    hits = hits_among(dirs, triangles, np.tile(np.arange(len(triangles)), (len(dirs), 1)))
    seen = full.tri.ravel() >= 0
    assert np.array_equal(hits.tri, full.tri.ravel())
    assert np.allclose(hits.distance[seen], full.distance.ravel()[seen])
    assert np.allclose(hits.bary[seen], full.bary.reshape(-1, 2)[seen])
    assert np.isinf(hits.distance[~seen]).all()


def test_missing_candidates_mean_no_hit_and_the_nearest_candidate_wins(triangles):
    full = trace_panorama(triangles, 96, 48)
    dirs = full.directions.reshape(-1, 3)
    first = full.tri.ravel()
    pick = np.flatnonzero(first >= 0)[:200]
    # The true triangle among others and an empty slot; then an empty list.
    others = np.stack([np.full(len(pick), -1), (first[pick] + 7) % len(triangles), first[pick]], axis=1)
    hits = hits_among(dirs[pick], triangles, others)
    assert np.array_equal(hits.tri, first[pick])
    none = hits_among(dirs[pick], triangles, np.full((len(pick), 2), -1))
    assert (none.tri == -1).all() and np.isinf(none.distance).all()


@pytest.mark.parametrize("window", [(10, 20, 80, 30), (0, 48, 0, 96), (30, 18, 5, 12), (0, 6, 0, 96)])
def test_a_window_holds_the_same_hits_as_the_whole_panorama(triangles, window):
    full = trace_panorama(triangles, 96, 48)
    part = trace_panorama(triangles, 96, 48, window=window)
    row0, rows, col0, cols = window
    columns = np.mod(col0 + np.arange(cols), 96)  # (80, 30) wraps round the seam
    assert part.tri.shape == (rows, cols)
    assert np.array_equal(part.tri, full.tri[row0:row0 + rows][:, columns])
    assert np.array_equal(part.distance, full.distance[row0:row0 + rows][:, columns])
    assert np.allclose(part.directions, full.directions[row0:row0 + rows][:, columns])
