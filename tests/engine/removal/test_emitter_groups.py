"""Important senders side by side on one plane are one emitter, sharing its rays at a pixel."""
from __future__ import annotations

import numpy as np

from addon.geometry.patches import triangle_samples
from addon.light.transport import make_senders
from addon.removal.emitter_groups import GROUP_SAMPLES, emitter_groups, sample_counts


def _senders():
    """A window in the wall x = 3 split into four triangles (two quads side by side), a lamp on
    the ceiling and a patch of the same wall far from the window."""
    window = np.array([
        [[3, 0, 0], [3, 1, 0], [3, 1, 1]], [[3, 0, 0], [3, 1, 1], [3, 0, 1]],
        [[3, 1, 0], [3, 2, 0], [3, 2, 1]], [[3, 1, 0], [3, 2, 1], [3, 1, 1]],
    ], dtype=float)
    lamp = np.array([[[0, 0, 2], [0.2, 0, 2], [0, 0.2, 2]]], dtype=float)
    far_patch = np.array([[[3, 5, 0], [3, 6, 0], [3, 6, 1]]], dtype=float)
    tris = np.concatenate([window, lamp, far_patch])
    normals = np.array([[-1.0, 0, 0]] * 4 + [[0, 0, -1.0]] + [[-1.0, 0, 0]])
    idx = np.arange(len(tris))
    return make_senders(tris, normals, np.ones((len(tris), 3)), np.zeros(len(tris), dtype=bool),
                        [(idx, triangle_samples(tris, 4))])


def test_patches_side_by_side_on_one_plane_are_one_emitter():
    groups = emitter_groups(_senders(), np.arange(6))
    of = groups.of
    assert len(set(of[:4])) == 1
    assert len({of[0], of[4], of[5]}) == 3
    assert sorted(groups.sizes.tolist()) == [1, 1, 4]


def test_an_emitters_rays_go_by_what_each_patch_sends_and_a_lamp_keeps_all():
    senders = _senders()
    groups = emitter_groups(senders, np.arange(6))
    pix = np.zeros(5, dtype=np.int64)
    s = np.array([0, 1, 2, 3, 4])
    light = np.array([8.0, 4.0, 2.0, 2.0, 1.0])
    counts = sample_counts(groups, pix, s, light, np.full(5, 16))
    assert counts[4] == 16  # the lamp alone in its emitter
    share = light[:4] / light[:4].sum()
    assert counts[:4].tolist() == np.clip(np.ceil(GROUP_SAMPLES * 16 * share), 1, 16).astype(int).tolist()
    assert counts[:4].sum() < 4 * 16


def test_no_important_senders_make_no_emitters():
    groups = emitter_groups(_senders(), np.zeros(0, dtype=np.int64))
    assert (groups.of == -1).all() and len(groups.sizes) == 0
