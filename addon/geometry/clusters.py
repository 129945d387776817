"""Clusters of a finely tessellated object's triangles, so that it costs a bounded number of patches.

A UV sphere of 2000 triangles would otherwise be 2000 senders and 2000 receivers, each tested for
visibility against every other patch. Its light is smooth over the surface, so a cluster of
neighbouring triangles that face about the same way can share one radiosity: k-means on the
triangles' centroids (in units of the object's size) and normals, weighted by area, started
from farthest points so the result is deterministic. Triangles the probe sees and ones it does
not are clustered apart: a cluster's radiosity comes from its pixels, and one straddling the
probe's view of the object's outline would give its unseen part the seen part's light.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

_ITERATIONS = 12  # Lloyd steps: the assignment settles within a few on smooth meshes
_SAMPLE = 8192  # triangles at most that the centres are fitted to
_CHUNK = 8192  # triangles assigned to their nearest centre at a time


@dataclass
class Clusters:
    """Triangles grouped into clusters: the label of each triangle and, per cluster, its area
    and the member triangle nearest the cluster's area-weighted centroid (a point and normal on
    the surface that stand for the cluster as a receiver, and its visibility sample)."""

    label: np.ndarray  # (T,) cluster of each triangle, 0..C-1
    area: np.ndarray  # (C,)
    representative: np.ndarray  # (C,) index of a member triangle


def cluster_triangles(centroids: np.ndarray, normals: np.ndarray, areas: np.ndarray, *, count: int,
                      size: float, kind: np.ndarray) -> Clusters:
    """Group triangles (centroids (T, 3), unit normals (T, 3), areas (T,)) into about `count`
    clusters; `size` (the object's radius) scales positions against normals (unit length).
    Triangles of different `kind` (T,) never share a cluster (the ones the probe sees take their
    light from pixels, the others from an estimate); each kind gets clusters by its area."""
    label = np.zeros(len(areas), dtype=np.int64)
    kinds = np.unique(kind)
    share = np.array([areas[kind == k].sum() for k in kinds]) / areas.sum()
    offset = 0
    for k, part in zip(kinds, share, strict=True):
        sel = np.flatnonzero(kind == k)
        label[sel] = offset + _kmeans(centroids[sel], normals[sel], areas[sel], max(1, round(count * part)), size)
        offset = label[sel].max() + 1
    area = np.bincount(label, areas)
    mean = np.stack([np.bincount(label, areas * centroids[:, c]) for c in range(3)], axis=1) / area[:, None]
    gap = np.linalg.norm(centroids - mean[label], axis=1)
    order = np.lexsort((gap, label))  # by cluster, nearest member first
    first = np.flatnonzero(np.r_[True, np.diff(label[order]) > 0])
    return Clusters(label, area, order[first])


def _kmeans(centroids: np.ndarray, normals: np.ndarray, areas: np.ndarray, count: int, size: float) -> np.ndarray:
    """(T,) labels 0..C-1 (C <= count, no empty cluster) of area-weighted k-means on positions
    in units of `size` and normals. The centres settle on an even sample of at most _SAMPLE
    triangles (a detailed mesh's neighbours say nothing more about where they go); every
    triangle then takes its nearest."""
    features = np.concatenate([centroids / max(size, 1e-12), normals], axis=1)
    count = min(count, len(features))
    sample = slice(None, None, -(-len(features) // _SAMPLE))
    some, weights = features[sample], areas[sample]
    centres = _farthest_points(some, count)
    for _ in range(_ITERATIONS):
        label = _nearest(some, centres)
        weight = np.bincount(label, weights, minlength=count)
        sums = np.stack([np.bincount(label, weights * column, minlength=count) for column in some.T], axis=1)
        # A centre that lost all its triangles stays where it was.
        centres = np.where(weight[:, None] > 0.0, sums / np.maximum(weight, 1e-300)[:, None], centres)
    return np.unique(_nearest(features, centres), return_inverse=True)[1]


def visibility_samples(clusters: Clusters, centroids: np.ndarray, areas: np.ndarray, *, k: int
                       ) -> tuple[np.ndarray, np.ndarray]:
    """(C, k) member triangles spread over each cluster (its representative, then each time the
    member farthest from those chosen) and (C, k) the area of the members nearest to each: the
    visibility samples of a cluster and their weights. One sample would see a cluster across an
    object's outline, from a receiver that sees only part of it, as wholly hidden or shown."""
    label = clusters.label
    chosen = [clusters.representative]
    dist = np.linalg.norm(centroids - centroids[chosen[0][label]], axis=1)
    for _ in range(k - 1):
        order = np.lexsort((-dist, label))
        chosen.append(order[np.flatnonzero(np.r_[True, np.diff(label[order]) > 0])])
        dist = np.minimum(dist, np.linalg.norm(centroids - centroids[chosen[-1][label]], axis=1))
    members = np.stack(chosen, axis=1)
    nearest = np.linalg.norm(centroids[:, None, :] - centroids[members[label]], axis=2).argmin(axis=1)
    weights = np.zeros(members.shape)
    np.add.at(weights, (label, nearest), areas)
    return members, weights


def _farthest_points(features: np.ndarray, count: int) -> np.ndarray:
    """(count, F) starting centres: the first feature row, then each time the row farthest from
    the chosen ones (spreads the clusters over the whole object)."""
    chosen = [0]
    dist = np.linalg.norm(features - features[0], axis=1)
    for _ in range(count - 1):
        chosen.append(int(dist.argmax()))
        dist = np.minimum(dist, np.linalg.norm(features - features[chosen[-1]], axis=1))
    return features[chosen]


def _nearest(features: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """(N,) the nearest of `centres` (C, F) to each of `features` (N, F), _CHUNK rows at a time:
    the (N, C) distances of a 200k-triangle object would be 150 MB per temporary."""
    out = np.empty(len(features), dtype=np.int64)
    c2 = (centres**2).sum(axis=1)[None]
    for i0 in range(0, len(features), _CHUNK):
        f = features[i0 : i0 + _CHUNK]
        out[i0 : i0 + _CHUNK] = ((f**2).sum(axis=1)[:, None] - 2.0 * f @ centres.T + c2).argmin(axis=1)
    return out
