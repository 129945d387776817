"""Patch lattices: areas add up, points locate in the right patch, interpolation is exact for linear fields."""
import numpy as np

from addon.geometry.patches import build_lattice, levels_for_count, levels_for_size, split_triangles, triangle_samples


def _random_points(tris, tri, rng):
    b = rng.random((len(tri), 2))
    flip = b.sum(axis=1) > 1
    b[flip] = 1 - b[flip]
    t = tris[tri]
    return b, t[:, 0] + b[:, :1] * (t[:, 1] - t[:, 0]) + b[:, 1:] * (t[:, 2] - t[:, 0])


def test_patches_tile_their_triangle():
    rng = np.random.default_rng(1)
    tris = rng.normal(size=(6, 3, 3))
    lat = build_lattice(tris, np.array([1, 2, 3, 5, 8, 0]))
    pt = lat.patch_triangles()
    area = np.linalg.norm(np.cross(pt[:, 1] - pt[:, 0], pt[:, 2] - pt[:, 0]), axis=1) / 2
    whole = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1) / 2
    assert np.allclose(np.bincount(lat.patch_tri, area, minlength=6)[:5], whole[:5])
    assert lat.n_patches == 1 + 4 + 9 + 25 + 64


def test_locate_reconstructs_points_and_linear_fields():
    rng = np.random.default_rng(2)
    tris = rng.normal(size=(4, 3, 3))
    lat = build_lattice(tris, np.array([1, 3, 7, 16]))
    tri = rng.integers(0, 4, 5000)
    bary, pts = _random_points(tris, tri, rng)
    patch, corners, w = lat.locate(tri, bary)
    assert (lat.patch_tri[patch] == tri).all()
    assert (w >= -1e-12).all() and np.allclose(w.sum(axis=1), 1)
    assert np.allclose(np.einsum("nk,nkc->nc", w, lat.vertices[corners]), pts)
    field = lat.vertices @ np.array([1.0, -2.0, 0.5])
    assert np.allclose(np.einsum("nk,nk->n", w, field[corners]), pts @ np.array([1.0, -2.0, 0.5]))


def test_levels_and_samples():
    tris = np.array([[[0, 0, 0], [4, 0, 0], [0, 4, 0]]], dtype=float)
    assert levels_for_size(tris, 1.0)[0] == 6  # longest edge 5.66 m
    many = np.repeat(tris, 10, axis=0)
    count = (levels_for_count(many, 1000) ** 2).sum()
    assert 500 <= count <= 2000
    s = triangle_samples(tris, 3)
    assert s.shape == (1, 9, 3) and np.allclose(s[0].mean(axis=0), tris[0].mean(axis=0))


def test_split_triangles_tile_the_triangle_around_the_samples():
    rng = np.random.default_rng(3)
    tris = rng.normal(size=(3, 3, 3))
    sub = split_triangles(tris, 4)
    assert sub.shape == (3, 16, 3, 3)
    area = np.linalg.norm(np.cross(sub[..., 1, :] - sub[..., 0, :], sub[..., 2, :] - sub[..., 0, :]), axis=-1) / 2
    whole = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1) / 2
    assert np.allclose(area, whole[:, None] / 16)  # congruent, and together the whole triangle
    assert np.allclose(sub.mean(axis=2), triangle_samples(tris, 4))
