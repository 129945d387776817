"""Blocked segments: the hierarchy and its shortcuts give exactly the answers of testing every
triangle, for closed and open meshes, fine and coarse ones, and the segments that matter most:
through the solid, ending on its surface, and grazing its edges."""
import numpy as np
import pytest

from addon.geometry import bvh, solid
from addon.geometry.occluders import Occluders
from addon.geometry.patches import split_triangles
from tests.engine.tiny_room import box_triangles as box

EPS = 1e-6


def _brute_force(tris: np.ndarray, p0: np.ndarray, p1: np.ndarray, eps: float) -> np.ndarray:
    """Moller-Trumbore of every segment against every triangle, ends cut as Occluders cuts them."""
    d = p1 - p0
    tmin = np.minimum(30.0 * eps / np.linalg.norm(d, axis=1), 0.5)[:, None]
    v0, e1, e2 = tris[:, 0], tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]
    out = np.zeros(len(p0), dtype=bool)
    for i0 in range(0, len(p0), 200):
        o, r, t0 = p0[i0 : i0 + 200, None], d[i0 : i0 + 200, None], tmin[i0 : i0 + 200]
        p = np.cross(r, e2)
        det = np.einsum("tc,ntc->nt", e1, p)
        ok = np.abs(det) > 1e-20
        inv = 1.0 / np.where(ok, det, 1.0)
        s = o - v0
        u = np.einsum("ntc,ntc->nt", s, p) * inv
        q = np.cross(s, e1)
        v = np.einsum("ntc,ntc->nt", r, q) * inv
        t = np.einsum("tc,ntc->nt", e2, q) * inv
        out[i0 : i0 + 200] = (ok & (u >= 0) & (v >= 0) & (u + v <= 1) & (t > t0) & (t < 1 - t0)).any(axis=1)
    return out


def _rotation(seed: int) -> np.ndarray:
    q = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))[0]
    return q * np.sign(np.linalg.det(q))


def _sphere(n: int) -> np.ndarray:
    """A closed UV sphere of radius 0.5 around (0.2, -0.1, 0.3)."""
    th, ph = np.linspace(0, np.pi, n // 2 + 1), np.linspace(0, 2 * np.pi, n + 1)
    th, ph = np.meshgrid(th, ph, indexing="ij")
    v = 0.5 * np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1) + [0.2, -0.1, 0.3]
    v[:, -1] = v[:, 0]  # the seam shares its vertices exactly
    a, b, c, d = v[:-1, :-1], v[1:, :-1], v[1:, 1:], v[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, c], axis=2), np.stack([a, c, d], axis=2)]).reshape(-1, 3, 3)
    area = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1)
    return tris[area > 1e-12]


def _fine_box(k: int, seed: int) -> np.ndarray:
    """A rotated box, each of its triangles split into k^2."""
    tris = split_triangles(box([-0.4, -0.3, -0.25], [0.4, 0.3, 0.25]), k).reshape(-1, 3, 3)
    return tris @ _rotation(seed).T + [0.1, 0.2, -0.1]


MESHES = {
    "coarse box": lambda: box([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]) @ _rotation(1).T,
    "fine rotated box": lambda: _fine_box(12, 2),
    "sphere": lambda: _sphere(40),
    "open box (no lid)": lambda: _fine_box(6, 3)[:-2 * 36],
    "two boxes, one object": lambda: np.concatenate([_fine_box(4, 4), _fine_box(3, 5) + np.array([1.5, 0.0, 0.0])]),
}


def _segments(tris: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Random segments around the mesh, segments between random points and points on its
    surface and between two points on it, and segments through points a hair's breadth beside
    its edges."""
    lo, hi = tris.reshape(-1, 3).min(axis=0), tris.reshape(-1, 3).max(axis=0)
    pad = 0.5 * (hi - lo)
    around = [rng.uniform(lo - pad, hi + pad, (3000, 3)) for _ in range(2)]
    pick = rng.integers(0, len(tris), 2000)
    w = rng.dirichlet([1, 1, 1], 2000)
    on = np.einsum("nk,nkc->nc", w, tris[pick])
    # A segment within a face's plane has no answer in floating point (its hits on that
    # plane are rounding), so two points on the surface are joined only across planes.
    normal = np.cross(tris[pick, 1] - tris[pick, 0], tris[pick, 2] - tris[pick, 0])[:1000]
    across = on[1000:] - on[:1000]
    across = np.abs(np.einsum("ij,ij->i", normal, across)) > 1e-6 * np.linalg.norm(normal, axis=1) * np.linalg.norm(
        across, axis=1)
    start = rng.uniform(lo - pad, hi + pad, (2000, 3))
    edge = rng.integers(0, 3, 1500)
    pick = rng.integers(0, len(tris), 1500)
    a, b = tris[pick, edge], tris[pick, (edge + 1) % 3]
    near_edge = a + rng.uniform(0, 1, (1500, 1)) * (b - a) + rng.normal(size=(1500, 3)) * 10 * EPS
    direction = rng.normal(size=(1500, 3))
    p0 = np.concatenate([around[0], start, on, on[:1000][across], near_edge - direction])
    p1 = np.concatenate([around[1], on, start, on[1000:][across], near_edge + direction])
    return p0, p1


@pytest.mark.parametrize("name", list(MESHES))
def test_blocked_is_exactly_the_test_of_every_triangle(name):
    tris = MESHES[name]()
    rng = np.random.default_rng(len(name))
    p0, p1 = _segments(tris, rng)
    occ = Occluders(tris, np.zeros(len(tris), int), EPS)
    expected = _brute_force(tris, p0, p1, EPS)
    got = occ.blocked(p0, p1)
    assert 0.1 < expected.mean() < 0.9
    assert (got == expected).all(), f"{(got != expected).sum()} segments differ"


def test_only_a_closed_surface_has_an_inside_and_it_is_inside():
    tris = _fine_box(6, 3)
    assert solid.closed(tris, EPS) and not solid.closed(tris[:-2], EPS)
    occ = Occluders(tris, np.zeros(len(tris), int), EPS)
    inner = np.concatenate([occ.objects[0].inner_lo, occ.objects[0].inner_hi], axis=2)[0].T  # (2K, 3): lo, hi
    assert occ.objects[0].inner_lo.shape[2] >= 1
    open_box = Occluders(tris[:-2], np.zeros(len(tris) - 2, int), EPS)
    assert open_box.objects[0].inner_lo.shape[2] == 0
    # The inside boxes' corners lie inside the box, in its own frame (half sizes 0.4, 0.3, 0.25).
    frame = occ.objects[0].frame
    local = solid.in_frame(solid.in_frame(inner, frame.T) - [0.1, 0.2, -0.1], _rotation(3).T)
    assert (np.abs(local) < [0.4, 0.3, 0.25]).all()


def test_the_frame_of_a_rotated_box_is_its_own():
    rotation = _rotation(7)
    tris = _fine_box(3, 7)
    frame = solid.principal_frame(tris)
    # Every axis of the frame is one of the box's axes, up to sign.
    np.testing.assert_allclose(np.sort(np.abs(frame @ rotation), axis=1), [[0, 0, 1]] * 3, atol=1e-9)


@pytest.mark.parametrize("count", [1, 7, 8, 9, 100, 1000])
def test_every_triangle_sits_in_exactly_one_leaf(count):
    tris = np.random.default_rng(count).uniform(-1, 1, (count, 3, 3))
    tree = bvh.build(tris, tris, EPS)
    v0 = tree.leaves[:, 0:3].transpose(0, 2, 1).reshape(-1, 3)
    found = (np.abs(v0[None] - tris[:, None, 0]).max(axis=2) == 0).any(axis=1)
    assert found.all() and len(tree.leaves) * bvh.LEAF < 2 * count + bvh.LEAF


def test_segments_blocked_by_an_axis_aligned_box_match_the_slab_test():
    rng = np.random.default_rng(0)
    obstacle = box([0.0, 0.0, 0.0], [1.0, 1.0, 1.0])
    occ = Occluders(obstacle, np.zeros(12, int), 1e-9)
    p0 = rng.uniform(-1, 2, (30000, 3))
    p1 = rng.uniform(-1, 2, (30000, 3))
    outside = ~((p0 > 0) & (p0 < 1)).all(axis=1) & ~((p1 > 0) & (p1 < 1)).all(axis=1)
    p0, p1 = p0[outside], p1[outside]  # light never starts inside a solid
    # An axis-aligned box is its own bounding box: the slab test is the exact answer.
    d = p1 - p0
    with np.errstate(divide="ignore", invalid="ignore"):
        t0, t1 = (0.0 - p0) / d, (1.0 - p0) / d
    near = np.minimum(t0, t1).max(axis=1)
    far = np.maximum(t0, t1).min(axis=1)
    exact = (near < far) & (far > 0) & (near < 1)
    got = occ.blocked(p0, p1)
    assert exact.sum() > 1000 and (got == exact).all()
    # endpoints on the surface do not block themselves
    assert not occ.blocked(np.array([[0.5, 0.5, 1.0]]), np.array([[0.5, 0.5, 3.0]]))[0]
