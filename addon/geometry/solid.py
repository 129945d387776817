"""The shape of one object, for fast tests against it: the frame its faces align with, and
boxes certainly inside it when its surface is closed.

In a frame aligned with a piece of furniture its bounding box is tight and the boxes around
its flat faces are thin, so a segment that ends on a face or passes beside the object meets
few of them, and a receiver beside a face is told apart from the face's plane. A segment that
enters a region certainly inside a closed surface from a point outside its bounding box
crosses that surface: it is blocked with no triangle tested.
"""
from __future__ import annotations

import numpy as np

from .raycast import crossings

_GRID = 16  # cells per axis of the grid the inside is found on
_INNER_BOXES = 8  # the largest boxes of inside cells kept
_CELL_PAIRS = 1 << 20  # (triangle, cell) pairs tested at once
_DIRECTION_BIN = 0.05  # normals this close (per component) count as one direction
_SAMPLE = 4096  # triangles at most that choose the frame
# Rays of no special direction: one along a mesh's edge or through its vertex could count a
# crossing twice or not at all, and the three must agree.
_PARITY_RAYS = np.array([[0.5701, 0.3089, 0.7613], [-0.2873, 0.8652, -0.4109], [0.7071, -0.6284, 0.3241]])


def principal_frame(triangles: np.ndarray) -> np.ndarray:
    """(3, 3) a rotation (rows: the frame's axes) in which the triangles' bounding box is
    smallest, among: the axes as they are, the object's two most common face directions, and
    the principal axes of its surface; an even sample of a detailed object's triangles tells."""
    triangles = triangles[:: -(-len(triangles) // _SAMPLE)]
    cross = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    area = np.linalg.norm(cross, axis=1)
    keep = area > 0.0
    normals, area = cross[keep] / area[keep, None], area[keep]
    points = triangles.reshape(-1, 3)
    frames = [np.eye(3)]
    if len(area):
        first = _most_common(normals, area)
        side = np.abs(normals @ first) < _DIRECTION_BIN
        across = normals[side] - np.outer(normals[side] @ first, first)
        lengths = np.linalg.norm(across, axis=1)
        second = _most_common(across / lengths[:, None], area[side]) if side.any() else np.roll(first, 1)
        frames.append(_orthonormal(first, second))
        centroids = triangles[keep].mean(axis=1)
        centred = centroids - (area[:, None] * centroids).sum(axis=0) / area.sum()
        frames.append(np.linalg.eigh((centred * area[:, None]).T @ centred)[1].T)
    volumes = [np.prod(np.ptp(in_frame(points, f), axis=0)) for f in frames]
    # A frame must win clearly: the axes as they are keep the exact coordinates.
    best = int(np.argmin(volumes))
    return frames[best] if volumes[best] < 0.99 * volumes[0] else frames[0]


def in_frame(points: np.ndarray, frame: np.ndarray) -> np.ndarray:
    """Points (..., 3) in the frame whose axes are the rows of `frame` (by einsum: a matmul
    with a 3x3 matrix takes a slow path in numpy)."""
    return np.einsum("...j,kj->...k", points, frame)


def _most_common(directions: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """The weighted mean of the most common direction, up to sign, among unit rows."""
    flip = np.take_along_axis(directions, np.abs(directions).argmax(axis=1)[:, None], axis=1) < 0.0
    directions = np.where(flip, -directions, directions)
    key = _row_ids(np.round(directions / _DIRECTION_BIN).astype(np.int64))
    top = np.bincount(key, weight).argmax()
    mean = (directions[key == top] * weight[key == top, None]).sum(axis=0)
    return mean / np.linalg.norm(mean)


def _orthonormal(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    second = second - (second @ first) * first
    if np.linalg.norm(second) < 1e-6:
        second = np.cross(first, np.eye(3)[np.abs(first).argmin()])
    second /= np.linalg.norm(second)
    return np.stack([first, second, np.cross(first, second)])


def closed(triangles: np.ndarray, tolerance: float) -> bool:
    """Whether the triangles form closed surfaces: corners that meet within `tolerance` joined,
    every edge is shared by an even number of them (so inside and outside mean something)."""
    ids = _row_ids(np.round(triangles.reshape(-1, 3) / max(tolerance, 1e-300)).astype(np.int64)).reshape(-1, 3)
    edges = np.sort(np.stack([ids, np.roll(ids, -1, axis=1)], axis=-1).reshape(-1, 2), axis=1)
    _, counts = np.unique(edges[:, 0] * (int(ids.max()) + 1) + edges[:, 1], return_counts=True)
    return bool((counts % 2 == 0).all())


def _row_ids(rows: np.ndarray) -> np.ndarray:
    """(N,) an id shared by equal rows of an integer array (N, 3), 0.. in sorted order (as
    np.unique(axis=0) gives, which is many times slower)."""
    order = np.lexsort(rows.T[::-1])
    ordered = rows[order]
    new = np.r_[True, (ordered[1:] != ordered[:-1]).any(axis=1)]
    ids = np.empty(len(rows), dtype=np.int64)
    ids[order] = np.cumsum(new) - 1
    return ids


def inner_boxes(triangles: np.ndarray, margin: float) -> np.ndarray:
    """(K, 2, 3) boxes (lo, hi) certainly inside the closed surface that the triangles (T, 3, 3)
    form, K <= _INNER_BOXES: cells of a grid over their bounding box that no triangle comes
    within `margin` of and that lie inside it (every cell of a region of such cells is on the
    same side, which three rays from one of them tell), merged into boxes, largest first."""
    lo, hi = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
    size = np.maximum(hi - lo, 1e-300) / _GRID
    free = ~_touched(triangles, lo, size, margin)
    region = _regions(free)
    labels = np.unique(region[free])  # each the flat index of the region's first cell
    cells = np.stack(np.unravel_index(labels, free.shape), axis=1)
    origins = np.repeat(lo + (cells + 0.5) * size, len(_PARITY_RAYS), axis=0)
    odd = crossings(origins, np.tile(_PARITY_RAYS, (len(labels), 1)), triangles) % 2 == 1
    inside = np.isin(region, labels[odd.reshape(len(labels), -1).all(axis=1)])
    boxes = _merged(inside)[:_INNER_BOXES]
    return np.stack([lo + boxes[:, 0] * size, lo + boxes[:, 1] * size], axis=1)


def _touched(triangles: np.ndarray, lo: np.ndarray, size: np.ndarray, margin: float) -> np.ndarray:
    """(G, G, G) the cells that a triangle may come within `margin` of: its grown bounding box
    meets the cell and its plane passes near enough. The (triangle, cell) pairs are taken a
    batch of triangles at a time (a long sliver spans many cells)."""
    first = np.clip(np.floor((triangles.min(axis=1) - margin - lo) / size), 0, _GRID - 1).astype(np.int64)
    last = np.clip(np.floor((triangles.max(axis=1) + margin - lo) / size), 0, _GRID - 1).astype(np.int64)
    span = last - first + 1
    count = span.prod(axis=1)
    normal = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    reach = np.abs(normal) @ (0.5 * size) + margin * np.linalg.norm(normal, axis=1)
    out = np.zeros((_GRID,) * 3, dtype=bool)
    batch = np.cumsum(count) // _CELL_PAIRS
    for b in np.unique(batch):
        t = np.flatnonzero(batch == b)
        tri = np.repeat(t, count[t])
        rank = np.arange(len(tri)) - np.repeat(np.cumsum(count[t]) - count[t], count[t])
        cell = first[tri] + np.stack([rank // (span[tri, 1] * span[tri, 2]), rank // span[tri, 2] % span[tri, 1],
                                      rank % span[tri, 2]], axis=1)
        height = np.abs(np.einsum("ij,ij->i", normal[tri], lo + (cell + 0.5) * size - triangles[tri, 0]))
        out[tuple(cell[height <= reach[tri] * (1.0 + 1e-9)].T)] = True
    return out


def _regions(free: np.ndarray) -> np.ndarray:
    """(G, G, G) a label shared by the face-connected free cells of one region (the smallest
    cell index in it), -1 elsewhere."""
    big = free.size
    label = np.where(free, np.arange(big).reshape(free.shape), big)
    while True:
        low = label.copy()
        for axis in range(3):
            for shift in (1, -1):
                low = np.minimum(low, np.where(_edge_mask(axis, shift), big, np.roll(label, shift, axis=axis)))
        low = np.where(free, low, big)
        if (low == label).all():
            return np.where(free, label, -1)
        label = low


def _edge_mask(axis: int, shift: int) -> np.ndarray:
    """(G, G, G) the cells that np.roll by `shift` along `axis` fills from the opposite face."""
    index = np.arange(_GRID).reshape([-1 if a == axis else 1 for a in range(3)])
    return np.broadcast_to(index == (0 if shift > 0 else _GRID - 1), (_GRID,) * 3)


def _merged(cells: np.ndarray) -> np.ndarray:
    """(K, 2, 3) boxes (first cell, one past the last) that together cover the cells, each
    grown greedily along the last axis, then the middle, then the first; largest first."""
    left = cells.copy()
    boxes = []
    for start in np.argwhere(cells):
        if not left[tuple(start)]:
            continue
        end = start + 1
        for axis in (2, 1, 0):
            while end[axis] < _GRID:
                grown = end.copy()
                grown[axis] += 1
                block = left[start[0] : grown[0], start[1] : grown[1], start[2] : grown[2]]
                if not block.all():
                    break
                end = grown
        left[start[0] : end[0], start[1] : end[1], start[2] : end[2]] = False
        boxes.append((start, end))
    if not boxes:
        return np.zeros((0, 2, 3))
    boxes = np.array(boxes, dtype=np.float64)
    return boxes[np.argsort(-np.prod(boxes[:, 1] - boxes[:, 0], axis=1), kind="stable")]
