"""The binary labelling object / background of the free pixels of a window, by the convex
relaxation of the graph cut.

The energy is sum_p D_p x_p + sum_pq w_pq |x_p - x_q| over x in {0, 1} (D_p: the cost of calling
p object rather than background; w_pq: contrast-sensitive smoothness over the 8-neighbourhood).
Relaxed to u in [0, 1] it is an edge-weighted total variation with a linear data term, whose
thresholding at any level in (0, 1) is a global minimiser of the binary energy; the relaxation is
solved by the diagonally preconditioned primal-dual iteration (Pock and Chambolle), which is a few
array operations per step over the free pixels and their edges only.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

# The 8-neighbourhood as four offsets (each edge once), each weighted by 1 / its length: the cost
# of an outline then hardly depends on its direction (Cauchy-Crofton weights up to a factor).
_OFFSETS = ((0, 1, 1.0), (1, 0, 1.0), (1, 1, 2.0 ** -0.5), (1, -1, 2.0 ** -0.5))
# u lives in [0, 1] while the dual lives in [-w, w]: primal steps of _BALANCE / mean(w) of the
# preconditioned ones and dual steps mean(w) / _BALANCE times theirs keep the two in proportion,
# which converges several times faster than either extreme over smoothness 1 to 6.
_BALANCE = 0.5


@dataclass(frozen=True)
class Graph:
    """The smoothness terms among a window's free pixels, the fixed pixels folded in."""

    free: np.ndarray  # (n,) int64 flat indices of the free pixels
    first: np.ndarray  # (m,) intp free-pixel index of each edge's first end
    second: np.ndarray  # (m,) intp and of its second
    weight: np.ndarray  # (m,) float32 w_pq
    pull: np.ndarray  # (n,) float32 the linear term of the edges to fixed pixels
    degree: np.ndarray  # (n,) float32 edges among free pixels at each


@dataclass(frozen=True)
class Relaxation:
    """A state of the primal-dual iteration; `labels` is its thresholding."""

    u: np.ndarray  # (n,) float32 in [0, 1], over Graph.free
    dual: np.ndarray  # (m,) float32 in [-w, w], over Graph's edges

    @property
    def labels(self) -> np.ndarray:
        return self.u >= 0.5


def contrast_beta(features: np.ndarray, region: np.ndarray) -> float:
    """GrabCut's beta, 1 / (2 mean |f_p - f_q|^2) over the neighbour pairs touching `region`
    (h, w) bool of features (h, w, c); 0 for a flat region."""
    total, count = 0.0, 0
    for a, b, _ in _pairs(region.shape):
        touching = region[a] | region[b]
        total += float(((features[a][touching] - features[b][touching]) ** 2).sum())
        count += int(touching.sum())
    return 0.5 * count / total if total > 0.0 else 0.0


def contrast_graph(features: np.ndarray, free: np.ndarray, fixed: np.ndarray, *, smoothness: float,
                   beta: float) -> Graph:
    """The graph over the (h, w) bool `free` pixels, weights smoothness exp(-beta |f_p - f_q|^2)
    / |p - q| from features (h, w, c); `fixed` (h, w) bool holds the label of the other pixels."""
    h, w = free.shape
    index = np.full(h * w, -1, dtype=np.int64)
    flat_free = np.flatnonzero(free)
    n = len(flat_free)
    index[flat_free] = np.arange(n)
    index = index.reshape(h, w)
    pull = np.zeros(n)
    firsts, seconds, weights = [], [], []
    for a, b, length in _pairs(free.shape):
        touching = free[a] | free[b]
        ia, ib = index[a][touching], index[b][touching]
        d2 = ((features[a][touching] - features[b][touching]) ** 2).sum(-1)
        weight = smoothness * length * np.exp(-beta * d2)
        both = (ia >= 0) & (ib >= 0)
        firsts.append(ia[both])
        seconds.append(ib[both])
        weights.append(weight[both])
        # w |u_p - l_q| with l_q fixed is w u_p (l_q = 0) or w - w u_p (l_q = 1): linear in u_p.
        for mine, other_label in ((ia, fixed[b][touching]), (ib, fixed[a][touching])):
            one = (mine >= 0) & ~both
            pull += np.bincount(mine[one], weights=weight[one] * np.where(other_label[one], -1.0, 1.0),
                                minlength=n)
    # Pointer-sized indices: numpy would convert narrower ones on every gather of the iteration.
    first = np.concatenate(firsts).astype(np.intp)
    second = np.concatenate(seconds).astype(np.intp)
    degree = np.bincount(first, minlength=n) + np.bincount(second, minlength=n)
    return Graph(free=flat_free, first=first, second=second, weight=np.concatenate(weights).astype(np.float32),
                 pull=pull.astype(np.float32), degree=degree.astype(np.float32))


def labelled(graph: Graph, labels: np.ndarray) -> Relaxation:
    """The state that starts the iteration from labels (n,) bool of the free pixels."""
    return Relaxation(u=labels.astype(np.float32), dual=np.zeros(len(graph.weight), dtype=np.float32))


def relax(graph: Graph, data: np.ndarray, *, iterations: int, start: Relaxation | None = None) -> Relaxation:
    """`iterations` primal-dual steps on the energy of `graph` with data term D (n,) over its free
    pixels, from `start` (a previous solution, for another D) or from each pixel's own best label."""
    cost = (np.asarray(data, dtype=np.float32) + graph.pull).astype(np.float32)
    if start is None:
        start = labelled(graph, cost < 0.0)
    u, dual = start.u.copy(), start.dual.copy()
    n = len(u)
    balance = _BALANCE / float(graph.weight.mean()) if len(graph.weight) and graph.weight.mean() > 0 else 1.0
    tau = (balance / np.maximum(graph.degree, 1.0)).astype(np.float32)
    step_cost = tau * cost
    sigma = np.float32(0.5 / balance)
    first, second, upper = graph.first, graph.second, graph.weight
    lower = -upper
    ubar = u.copy()
    gap = np.empty_like(dual)
    other = np.empty_like(dual)
    for _ in range(iterations):
        np.take(ubar, first, out=gap)
        gap -= np.take(ubar, second, out=other)
        gap *= sigma
        dual += gap
        np.minimum(dual, upper, out=dual)
        np.maximum(dual, lower, out=dual)
        divergence = np.bincount(first, weights=dual, minlength=n)
        divergence -= np.bincount(second, weights=dual, minlength=n)
        # u_new = clip(u - tau (div + cost)); ubar = 2 u_new - u, with ubar holding u meanwhile.
        ubar[:] = u
        u -= tau * divergence.astype(np.float32)
        u -= step_cost
        np.clip(u, 0.0, 1.0, out=u)
        ubar *= -1.0
        ubar += 2.0 * u
    return Relaxation(u=u, dual=dual)


def _pairs(shape: tuple[int, int]) -> list[tuple[tuple[slice, slice], tuple[slice, slice], float]]:
    """For each offset of the 8-neighbourhood, the slices of an (h, w) array holding the first
    and the second pixel of every pair, and the pair's edge length."""
    h, w = shape
    return [((slice(0, h - dy), slice(max(0, -dx), w - max(0, dx))),
             (slice(dy, h), slice(max(0, dx), w + min(0, dx))), length) for dy, dx, length in _OFFSETS]
