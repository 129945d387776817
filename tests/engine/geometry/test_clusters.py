"""Clusters of a finely tessellated object: bounded, covering, deterministic; a sender made of
several triangles has the form factor of their union."""
import numpy as np

from addon.geometry.clusters import cluster_triangles, visibility_samples
from addon.light.formfactor import point_to_triangle
from addon.light.transport import Parts, form_factors, make_senders


def _sphere(n: int = 24) -> np.ndarray:
    """(T, 3, 3) a UV sphere of radius 1, outward winding."""
    th, ph = np.linspace(0, np.pi, n // 2 + 1), np.linspace(0, 2 * np.pi, n + 1)
    p = np.stack(np.meshgrid(th, ph, indexing="ij"), axis=-1)
    th, ph = p[..., 0], p[..., 1]
    v = np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], axis=-1)
    a, b, c, d = v[:-1, :-1], v[1:, :-1], v[1:, 1:], v[:-1, 1:]
    tris = np.concatenate([np.stack([a, b, c], axis=2), np.stack([a, c, d], axis=2)]).reshape(-1, 3, 3)
    area = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1) / 2
    return tris[area > 1e-9]


def _normals(tris):
    n = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    return n / np.linalg.norm(n, axis=1, keepdims=True)


def test_clusters_are_bounded_cover_every_triangle_and_repeat():
    tris = _sphere()
    cent, nrm = tris.mean(axis=1), _normals(tris)
    area = np.linalg.norm(np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0]), axis=1) / 2
    cl = cluster_triangles(cent, nrm, area, count=40, size=1.0, kind=cent[:, 2] > 0.3)
    assert 30 <= len(cl.area) <= 40 and np.allclose(cl.area.sum(), area.sum())
    assert (cl.label[cl.representative] == np.arange(len(cl.area))).all()
    # Neighbours share a cluster: every member faces within 60 degrees of its representative.
    assert (np.einsum("ij,ij->i", nrm, nrm[cl.representative[cl.label]]) > 0.5).all()
    again = cluster_triangles(cent, nrm, area, count=40, size=1.0, kind=cent[:, 2] > 0.3)
    assert (again.label == cl.label).all()
    # The two kinds never share a cluster.
    assert (np.bincount(cl.label, cent[:, 2] > 0.3) % np.bincount(cl.label) == 0).all()
    members, weights = visibility_samples(cl, cent, area, k=4)
    assert (cl.label[members] == np.arange(len(cl.area))[:, None]).all()
    assert np.allclose(weights.sum(axis=1), cl.area)


def test_a_sender_of_several_triangles_has_their_summed_form_factor():
    tris = _sphere(12) * 0.3 + np.array([0.0, 0.0, 1.0])
    nrm = _normals(tris)
    owner = np.arange(len(tris)) % 5
    points, up = np.array([[0.0, 0.0, 0.0], [0.5, 0.2, 0.0]]), np.tile([0.0, 0.0, 1.0], (2, 1))
    senders = make_senders(tris[:5], nrm[:5], np.ones((5, 3)), np.zeros(5, dtype=bool),
                           [(np.arange(5), tris[:5].mean(axis=1)[:, None, :])], Parts(tris, nrm, owner))
    f = form_factors(points, up, senders)
    each = point_to_triangle(points, up, tris, nrm)
    assert np.allclose(f, np.stack([each[:, owner == s].sum(axis=1) for s in range(5)], axis=1))
