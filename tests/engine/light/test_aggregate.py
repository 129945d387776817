"""Form factors to senders of many triangles: near receivers get the exact sum over the
members, far ones point patches within a small error, and nothing where nothing is seen."""
import numpy as np
import pytest

from addon.geometry.patches import split_triangles
from addon.light import aggregate
from addon.light.formfactor import point_to_triangle
from tests.engine.tiny_room import box_triangles


def _normals(tris: np.ndarray) -> np.ndarray:
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def _fine_box() -> tuple[np.ndarray, np.ndarray]:
    """A box standing on z = 0, turned about z, its triangles split into 12^2; outward normals."""
    tris = split_triangles(box_triangles([-0.25, -0.25, 0.0], [0.25, 0.25, 0.5]), 12).reshape(-1, 3, 3)
    turn = np.array([[np.cos(0.35), -np.sin(0.35), 0.0], [np.sin(0.35), np.cos(0.35), 0.0], [0.0, 0.0, 1.0]])
    tris = tris @ turn.T
    n = _normals(tris)
    return tris, np.where((np.einsum("ij,ij->i", n, tris.mean(axis=1) - [0, 0, 0.25]) < 0)[:, None], -n, n)


def _senders(tris: np.ndarray, count: int) -> np.ndarray:
    """Owner of each triangle: `count` compact patches of the surface (k-means on centroids)."""
    c = tris.mean(axis=1)
    centres = c[np.linspace(0, len(c) - 1, count).astype(int)]
    for _ in range(8):
        owner = ((c[:, None] - centres[None]) ** 2).sum(axis=2).argmin(axis=1)
        centres = np.stack([c[owner == k].mean(axis=0) if (owner == k).any() else centres[k] for k in range(count)])
    return np.unique(owner, return_inverse=True)[1].ravel()


def _exact(points, normals, tris, tri_normals, owner):
    member = point_to_triangle(points, normals, tris, tri_normals)
    return np.stack([np.bincount(owner, row, minlength=owner.max() + 1) for row in member])


@pytest.fixture(scope="module")
def scene():
    tris, normals = _fine_box()
    owner = _senders(tris, 30)
    rng = np.random.default_rng(3)
    # Floor points around the box, from touching it to far away, and points in the air.
    angle, dist = rng.uniform(0, 2 * np.pi, 600), 0.36 + rng.exponential(0.8, 600)
    floor = np.stack([dist * np.cos(angle), dist * np.sin(angle), np.zeros(600)], axis=1)
    air = rng.uniform([-3, -3, 0.0], [3, 3, 2.5], (400, 3))
    air = air[np.abs(air[:, :2]).max(axis=1) > 0.4]
    up = np.tile([0.0, 0.0, 1.0], (len(floor), 1))
    facing = rng.normal(size=(len(air), 3))
    facing /= np.linalg.norm(facing, axis=1, keepdims=True)
    points, receiver_normals = np.concatenate([floor, air]), np.concatenate([up, facing])
    tree = aggregate.hierarchy(tris, normals, owner, owner.max() + 1)
    return dict(points=points, normals=receiver_normals, tree=tree,
                approx=aggregate.form_factors(points, receiver_normals, tree),
                exact=_exact(points, receiver_normals, tris, normals, owner))


def test_a_receivers_light_from_the_object_is_within_a_percent(scene):
    total, approx = scene["exact"].sum(axis=1), scene["approx"].sum(axis=1)
    seen = total > 1e-4
    assert seen.sum() > 300
    error = np.abs(approx[seen] - total[seen]) / total[seen]
    assert error.mean() < 0.005 and error.max() < 0.03


def test_receivers_that_see_nothing_get_exactly_nothing(scene):
    nothing = scene["exact"] == 0.0
    assert nothing.sum() > 1000 and (scene["approx"][nothing] == 0.0).all()


def test_receivers_beside_the_object_get_the_exact_sum():
    tris, normals = _fine_box()
    owner = _senders(tris, 30)
    tree = aggregate.hierarchy(tris, normals, owner, owner.max() + 1)
    # A centimetre from the foot of a side, well within FAR radii of its groups: every member
    # that matters is summed exactly.
    side = np.flatnonzero(np.abs(normals[:, 2]) < 0.5)
    foot = side[tris[side, :, 2].min(axis=1) == 0.0][::7]
    points = tris[foot].mean(axis=1) * [1, 1, 0] + 0.01 * normals[foot]
    up = np.tile([0.0, 0.0, 1.0], (len(points), 1))
    exact = _exact(points, up, tris, normals, owner).sum(axis=1)
    assert len(points) > 5 and (exact > 0.2).all()
    np.testing.assert_allclose(aggregate.form_factors(points, up, tree).sum(axis=1), exact, rtol=1e-3)


def test_a_single_member_sender_and_a_coarse_mesh_are_exact():
    tris, normals = box_triangles([0, 0, 0], [1, 1, 1]), None
    normals = _normals(tris)
    owner = np.arange(12) // 2
    tree = aggregate.hierarchy(tris, normals, owner, 6)
    points = np.array([[0.5, 0.5, -0.2], [1.5, 0.3, 0.4], [-0.1, -0.1, 1.3]])
    dirs = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.6, 0.0, -0.8]])
    np.testing.assert_allclose(aggregate.form_factors(points, dirs, tree), _exact(points, dirs, tris, normals, owner),
                               rtol=1e-12, atol=1e-15)


def test_a_nearer_point_patch_threshold_opens_fewer_groups_beside_a_fine_mesh_within_two_percent(monkeypatch):
    # Floor points a few millimetres to 5 cm from a box of 10,800 triangles: where a draft
    # refines its contact shadow, and where the groups opened cost the most.
    tris = split_triangles(box_triangles([-0.25, -0.25, 0.0], [0.25, 0.25, 0.5]), 30).reshape(-1, 3, 3)
    normals = _normals(tris)
    normals = np.where((np.einsum("ij,ij->i", normals, tris.mean(axis=1) - [0, 0, 0.25]) < 0)[:, None], -normals,
                       normals)
    owner = _senders(tris, 40)
    tree = aggregate.hierarchy(tris, normals, owner, owner.max() + 1)
    rng = np.random.default_rng(1)
    angle, gap = rng.uniform(0, 2 * np.pi, 300), rng.uniform(0.005, 0.05, 300)
    along = np.stack([np.cos(angle), np.sin(angle)], axis=1)
    points = np.concatenate([along * (0.25 / np.abs(along).max(axis=1) + gap)[:, None], np.zeros((300, 1))], axis=1)
    up = np.tile([0.0, 0.0, 1.0], (len(points), 1))
    exact = _exact(points, up, tris, normals, owner).sum(axis=1)
    tested = []
    point_patches = aggregate._point_patches
    monkeypatch.setattr(aggregate, "_point_patches", lambda *a: (tested.append(len(a[0])), point_patches(*a))[1])
    error = {}
    for far in (aggregate.FAR, 3.0):
        tested.clear()
        got = aggregate.form_factors(points, up, tree, far=far).sum(axis=1)
        error[far] = (np.abs(got - exact) / exact, sum(tested))
    (fine, opened_fine), (coarse, opened_coarse) = error.values()
    assert opened_coarse < 0.97 * opened_fine
    assert fine.mean() < coarse.mean() < 0.01 and coarse.max() < 0.02
