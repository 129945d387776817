"""Compose a hole from shifted copies of the visible texture: one shift per pixel, chosen by an MRF.

Each hole pixel copies the known pixel a shift away (Pritch et al.'s shift-map; He and Sun
2012 draw the shifts from the texture's own repeats, `translations`). The labelling minimises
the seams: neighbours with different shifts pay for how much their two copies disagree at both
pixels, and a pixel next to the known surroundings pays for how much its copy disagrees with
them there, so tile and plank lines run on through the hole in phase. The MRF is solved by
min-sum belief propagation on blocks of pixels (one shift per block), then settled pixel by
pixel (iterated conditional modes, the two colours of a checkerboard in turn).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .translations import relative_difference

_MAX_BLOCKS = 800  # blocks the belief propagation runs on: its cost is blocks x shifts^2
_ITERATIONS = 16
_DAMPING = 0.5
_SWEEPS = 2  # pixel-level ICM sweeps after the blocks (each both checkerboard colours)
_TRUNCATE = 4.0  # one seam edge costs at most this many times the texture's variance
_UNREACHABLE = 1e3  # times the variance: a shift whose source is not known
_RESOLUTION = 0.5  # times the variance per octave a source is coarser than the pixel it fills
# A repainted pixel (something else seen there, or the material under a highlight) is no border
# to match, but what the photograph shows there still tells which copies are likely: this share
# of the truncated disagreement. Without it the repainted band costs nothing, and a copy of a line
# that ends in it is as cheap as plain floor: on bench_photo_groundtruth's workshop_box at
# 512x256 a painted lane's bend was copied as a bar off the lane (mean error 0.088, total 0.514);
# with shares 0.175-0.375 the bar is gone (0.030-0.032, 0.365; at 256x128 total 0.367 -> 0.361),
# the other photo scenes unchanged.
_GUIDE = 0.25
NEIGHBOURS4 = ((0, 1), (1, 0), (0, -1), (-1, 0))  # (dy, dx) of a pixel's 4-neighbours


@dataclass(frozen=True)
class ShiftMap:
    """`image` with the hole pixels that a shift reaches copied from the known pixel
    `shifts[labels]` away; `labels` (H, W) is -1 outside the hole and where no shift reaches
    known texture. `cost` is the labelling's seam cost per hole pixel, in units of the
    texture's variance."""

    image: np.ndarray
    labels: np.ndarray
    shifts: np.ndarray
    cost: float

    @property
    def covered(self) -> np.ndarray:
        return self.labels >= 0


def candidate_shifts(translations: np.ndarray, hole: np.ndarray, *, along: int = 4, seed: int = 0) -> np.ndarray:
    """The shifts to choose from: the texture's translations, and shifts along the raster's
    axes (which follow the floor's edges) of `along` lengths up to 1.5 times the hole's extent,
    each jittered by up to 15 % as the `seed` draws. The axis shifts continue a plank or a tile
    row from its visible ends whatever the lengths of the planks, which the translations alone
    cannot when their shades differ."""
    extent = hole_extent(hole)
    jitter = 1.0 + 0.15 * (2 * np.random.default_rng(seed).random(along) - 1) if seed else np.ones(along)
    lengths = np.unique(np.maximum(np.rint(extent * 1.5 ** (np.arange(along) - along + 2) * jitter), 2
                                   ).astype(np.int64))
    axis = np.concatenate([np.stack([0 * lengths, s * lengths], axis=1) for s in (1, -1)]
                          + [np.stack([s * lengths, 0 * lengths], axis=1) for s in (1, -1)])
    shifts = np.concatenate([np.asarray(translations, np.int64).reshape(-1, 2), axis])
    _, first = np.unique(shifts, axis=0, return_index=True)
    return shifts[np.sort(first)]


def lattice_shifts(translations: np.ndarray, image: np.ndarray, known: np.ndarray, hole: np.ndarray, *,
                   count: int = 24, min_shift: int = 6, seed: int = 0) -> np.ndarray:
    """The shifts to choose from on a periodic texture: its translations, their opposites, sums,
    differences and doubles, at least `min_shift` and at most 1.5 times the hole's extent long,
    the `count` that match the known surroundings best (`relative_difference`; those too long to
    check last, shortest first), none within 1.5 cells of a better one. A `seed` other than 0
    ranks them by a score scattered by up to 30 %: another set of good repeats, another choice of
    copies, equally in phase. Every label is a repeat, so neighbouring copies stay in phase; a
    shift along the floor's axes of some other length puts tiles out of phase wherever the
    border cannot tell (a band of shadow the lighting stage left there reads as a dark tile)."""
    base = np.asarray(translations, np.int64).reshape(-1, 2)
    base = np.concatenate([base, -base])
    i, j = np.triu_indices(len(base), 1)
    lattice = np.unique(np.concatenate([base, base[i] + base[j], 2 * base]), axis=0)
    extent = hole_extent(hole)
    length = np.hypot(*lattice.T)
    lattice = lattice[(length >= min_shift) & (length <= max(1.5 * extent, np.hypot(*base.T).max()))]
    score = relative_difference(image, known, hole, lattice)
    if seed:
        score = score * (1.0 + 0.3 * (2 * np.random.default_rng(seed).random(len(score)) - 1))
    order = np.lexsort((np.hypot(*lattice.T), score))
    chosen: list[np.ndarray] = []
    for s in lattice[order]:
        if len(chosen) == count:
            break
        if not chosen or np.hypot(*(np.asarray(chosen) - s).T).min() > 1.5:
            chosen.append(s)
    return np.asarray(chosen, np.int64).reshape(-1, 2)


def hole_extent(hole: np.ndarray) -> int:
    """The hole's bounding box's longer side, in cells."""
    ys, xs = np.nonzero(hole)
    return max(int(np.ptp(ys)), int(np.ptp(xs)), 1) + 1


def shift_map(image: np.ndarray, known: np.ndarray, hole: np.ndarray, shifts: np.ndarray, *,
              footprint: np.ndarray | None = None, guide: np.ndarray | None = None,
              guided: np.ndarray | None = None) -> ShiftMap:
    """The labelling of the `hole` pixels of `image` (H, W, C) with `shifts` (K, 2) whose copies
    of `known` pixels show the fewest seams. `footprint` (H, W), where given, is how coarsely
    the photograph resolves each pixel: sources coarser than the pixel they fill cost extra, so
    the sharp near floor is copied rather than the blurred far floor. `guide` (H, W, C), where
    given, is what the photograph shows at the `guided` hole pixels (repainted, not hidden): a
    copy there pays a share (`_GUIDE`) of how much it disagrees with it."""
    image = np.asarray(image, np.float32)
    hole = np.asarray(hole, bool)
    known = np.asarray(known, bool) & ~hole
    ys, xs = np.nonzero(hole)
    shifts = np.asarray(shifts, np.int64).reshape(-1, 2)
    labels = np.full(hole.shape, -1, np.int64)
    if not len(ys) or not len(shifts) or not known.any():
        return ShiftMap(image.copy(), labels, shifts, 0.0)
    variance = max(float(2 * image[known].var(axis=0).sum()), 1e-12)
    copies, reach = _copies(image, known, ys, xs, shifts)
    unary = np.where(reach, 0.0, _UNREACHABLE).astype(np.float32)
    unary += _border_cost(image, known, hole, ys, xs, shifts, variance)
    if guide is not None and guided is not None:
        unary += _guide_cost(copies, np.asarray(guide, np.float32)[ys, xs], np.asarray(guided, bool)[ys, xs], variance)
    if footprint is not None:
        src_fp = _at(footprint, ys[:, None] + shifts[:, 0], xs[:, None] + shifts[:, 1])
        octaves = np.log2(np.maximum(src_fp, 1e-30) / np.maximum(footprint[ys, xs], 1e-30)[:, None])
        unary += _RESOLUTION * np.maximum(octaves, 0.0).astype(np.float32)
    index = np.full(hole.shape, -1, np.int64)
    index[ys, xs] = np.arange(len(ys))
    pairs = _hole_pairs(index)
    label = _block_labels(unary, copies, pairs, ys, xs, variance)
    label, cost = _settle(label, (ys + xs) % 2, unary, copies, pairs, variance)
    ok = reach[np.arange(len(ys)), label]
    labels[ys[ok], xs[ok]] = label[ok]
    out = image.copy()
    out[ys[ok], xs[ok]] = copies[np.arange(len(ys)), label][ok]
    return ShiftMap(out, labels, shifts, cost / len(ys))


def _at(a: np.ndarray, y: np.ndarray, x: np.ndarray) -> np.ndarray:
    h, w = a.shape[:2]
    return a[np.clip(y, 0, h - 1), np.clip(x, 0, w - 1)]


def _copies(image: np.ndarray, known: np.ndarray, ys: np.ndarray, xs: np.ndarray, shifts: np.ndarray
            ) -> tuple[np.ndarray, np.ndarray]:
    """(N, K, C) what each shift copies to each hole pixel, and (N, K) whether that is known."""
    h, w = known.shape
    sy, sx = ys[:, None] + shifts[:, 0], xs[:, None] + shifts[:, 1]
    reach = (sy >= 0) & (sy < h) & (sx >= 0) & (sx < w) & _at(known, sy, sx)
    return np.where(reach[..., None], _at(image, sy, sx), 0.0).astype(np.float32), reach


def _guide_cost(copies: np.ndarray, guide: np.ndarray, guided: np.ndarray, variance: float) -> np.ndarray:
    """(N, K) `_GUIDE` times each copy's truncated disagreement with `guide` (N, C) at the
    `guided` (N,) pixels, 0 elsewhere: where the photograph shows something far from every copy
    (a chair's leg), all copies pay the same truncation and none is preferred."""
    diff = np.minimum(np.square(copies - guide[:, None]).sum(axis=2) / variance, _TRUNCATE)
    return np.where(guided[:, None], _GUIDE * diff, 0.0).astype(np.float32)


def _border_cost(image: np.ndarray, known: np.ndarray, hole: np.ndarray, ys: np.ndarray, xs: np.ndarray,
                 shifts: np.ndarray, variance: float) -> np.ndarray:
    """(N, K) for each hole pixel and shift: how much the copy disagrees with the known pixels
    beside it, at those pixels (truncated per neighbour; a copy that cannot be checked there
    costs the truncation)."""
    h, w = hole.shape
    cost = np.zeros((len(ys), len(shifts)), np.float32)
    for dy, dx in NEIGHBOURS4:
        qy, qx = ys + dy, xs + dx
        inside = (qy >= 0) & (qy < h) & (qx >= 0) & (qx < w)
        beside = inside & _at(known, qy, qx)
        if not beside.any():
            continue
        sel = np.flatnonzero(beside)
        moved, reach = _copies(image, known, qy[sel], qx[sel], shifts)
        diff = np.square(moved - image[qy[sel], qx[sel]][:, None]).sum(axis=2) / variance
        cost[sel] += np.where(reach, np.minimum(diff, _TRUNCATE), _TRUNCATE)
    return cost


def _hole_pairs(index: np.ndarray) -> np.ndarray:
    """(E, 2) hole-pixel indices of the 4-neighbour pairs inside the hole."""
    pairs = []
    for a, b in ((index[:, :-1], index[:, 1:]), (index[:-1], index[1:])):
        both = (a >= 0) & (b >= 0)
        pairs.append(np.stack([a[both], b[both]], axis=1))
    return np.concatenate(pairs)


def _pair_cost(copies: np.ndarray, i: np.ndarray, j: np.ndarray, variance: float) -> np.ndarray:
    """(E, K, K) the seam between pixels i and j when i takes shift a and j shift b: how much
    the two copies disagree at i and at j, truncated."""
    ci, cj = copies[i], copies[j]

    def disagree(c: np.ndarray) -> np.ndarray:
        sq = np.square(c).sum(axis=2)
        return sq[:, :, None] + sq[:, None, :] - 2 * np.einsum("eac,ebc->eab", c, c)

    return np.minimum(np.maximum(disagree(ci) + disagree(cj), 0.0) / variance, _TRUNCATE).astype(np.float32)


@dataclass(frozen=True)
class _Groups:
    """Rows of (E, ...) arrays summed into `n` rows by a fixed index (sorted once, then
    np.add.reduceat: np.add.at is several times slower, and message passing sums every iteration)."""

    order: np.ndarray
    starts: np.ndarray
    targets: np.ndarray
    n: int

    @classmethod
    def of(cls, index: np.ndarray, n: int) -> _Groups:
        order = np.argsort(index, kind="stable")
        sorted_index = index[order]
        starts = np.flatnonzero(np.r_[True, sorted_index[1:] != sorted_index[:-1]]) if len(index) else order
        return cls(order, starts, sorted_index[starts], n)

    def sum(self, values: np.ndarray) -> np.ndarray:
        return self.add_into(np.zeros((self.n, *values.shape[1:]), values.dtype), values)

    def add_into(self, out: np.ndarray, values: np.ndarray) -> np.ndarray:
        if len(self.order):
            out[self.targets] += np.add.reduceat(values[self.order], self.starts, axis=0)
        return out


def _block_labels(unary: np.ndarray, copies: np.ndarray, pairs: np.ndarray, ys: np.ndarray, xs: np.ndarray,
                  variance: float) -> np.ndarray:
    """(N,) a shift per hole pixel, one per block of pixels, by damped min-sum belief
    propagation over the blocks' adjacency (pairs inside a block cost nothing: one shift)."""
    side = max(1, int(np.ceil(np.sqrt(len(ys) / _MAX_BLOCKS))))
    by, bx = ys // side, xs // side
    _, block = np.unique(by * (bx.max() + 1) + bx, return_inverse=True)
    nb, k = int(block.max()) + 1, unary.shape[1]
    u = _Groups.of(block, nb).sum(unary)
    cross = block[pairs[:, 0]] != block[pairs[:, 1]]
    i, j = pairs[cross, 0], pairs[cross, 1]
    if not len(i):
        return np.broadcast_to(u.argmin(axis=1)[block], len(ys)).copy()
    # orient every crossing pair from its lower block to its higher one, then sum per block pair
    bi, bj = block[i], block[j]
    swap = bi > bj
    i, j = np.where(swap, j, i), np.where(swap, i, j)
    edge_key, edge = np.unique(block[i] * nb + block[j], return_inverse=True)
    order = np.argsort(edge, kind="stable")
    i, j, edge = i[order], j[order], edge[order]
    v = np.zeros((len(edge_key), k, k), np.float32)
    for lo in range(0, len(i), 4096):  # (E, K, K) temporaries in pieces; a block pair may span two
        _Groups.of(edge[lo:lo + 4096], len(edge_key)).add_into(v, _pair_cost(copies, i[lo:lo + 4096],
                                                                            j[lo:lo + 4096], variance))
    src, dst = edge_key // nb, edge_key % nb
    # directed edges: e and e + E are the two directions of one pair
    tail, head = np.concatenate([src, dst]), np.concatenate([dst, src])
    cost = np.concatenate([v, v.transpose(0, 2, 1)])  # cost[e][a, b]: tail takes a, head b
    reverse = np.concatenate([np.arange(len(src)) + len(src), np.arange(len(src))])
    messages = np.zeros((len(tail), k), np.float32)
    into = _Groups.of(head, nb)
    for _ in range(_ITERATIONS):
        incoming = u + into.sum(messages)
        h = incoming[tail] - messages[reverse]
        new = (h[:, :, None] + cost).min(axis=1)
        new -= new.min(axis=1, keepdims=True)
        messages = _DAMPING * messages + (1 - _DAMPING) * new
    return (u + into.sum(messages)).argmin(axis=1)[block]


def _settle(label: np.ndarray, colour: np.ndarray, unary: np.ndarray, copies: np.ndarray, pairs: np.ndarray,
            variance: float) -> tuple[np.ndarray, float]:
    """Pixel-level iterated conditional modes from `label`: each pixel, one checkerboard colour
    at a time (`colour`: a grid's neighbours differ in it), takes the shift that costs least
    given its neighbours' shifts; and the final total cost."""
    n = len(label)
    # directed: p's cost depends on q's shift
    p, q = np.concatenate([pairs[:, 1], pairs[:, 0]]), np.concatenate([pairs[:, 0], pairs[:, 1]])
    label = label.copy()
    sides = [(colour[p] == c, colour == c) for c in (0, 1)]
    into = [_Groups.of(p[sel], n) for sel, _ in sides]
    for _ in range(_SWEEPS):
        for (sel, mine), groups in zip(sides, into, strict=True):
            cost = unary + groups.sum(_seam_to(copies, p[sel], q[sel], label[q[sel]], variance))
            label[mine] = cost[mine].argmin(axis=1)
    total = float(unary[np.arange(n), label].sum())
    total += float(_seam_to(copies, pairs[:, 0], pairs[:, 1], label[pairs[:, 1]], variance)
                   [np.arange(len(pairs)), label[pairs[:, 0]]].sum())
    return label, total


def _seam_to(copies: np.ndarray, p: np.ndarray, q: np.ndarray, q_label: np.ndarray, variance: float) -> np.ndarray:
    """(E, K) the seam between p taking each shift and q keeping `q_label`, truncated."""
    cq_p = copies[p, q_label][:, None]  # q's copy at p
    cq_q = copies[q, q_label][:, None]
    d = np.square(copies[p] - cq_p).sum(axis=2) + np.square(copies[q] - cq_q).sum(axis=2)
    return np.minimum(d / variance, _TRUNCATE).astype(np.float32)
