"""The probe-frame geometry: which objects bound the room (and so can block no shadow ray)."""
from __future__ import annotations

import numpy as np

from addon.geometry import mesh
from addon.geometry.mesh import boundary_objects, build_geometry
from addon.geometry.patches import split_triangles
from tests.engine import tiny_room


def _geometry(box_split: int = 1):
    scene = tiny_room.scene_data(16, 8)
    box = scene.object_names.index("Box")
    on = scene.tri_object == box
    fine = split_triangles(scene.triangles[on], box_split).reshape(-1, 3, 3)
    triangles = np.concatenate([scene.triangles[~on], fine])
    owners = np.concatenate([scene.tri_object[~on], np.full(len(fine), box, dtype=scene.tri_object.dtype)])
    return build_geometry(triangles, owners, scene.object_names, scene.center, scene.rotation)


def _witnesses(geo) -> np.ndarray:
    return np.concatenate([geo.triangles.reshape(-1, 3), np.zeros((1, 3))])


def test_the_shell_and_floor_bound_the_room_and_the_box_and_lamp_do_not():
    geo = _geometry()
    bound = dict(zip(geo.object_names, boundary_objects(geo, _witnesses(geo)), strict=True))
    assert bound == {"Box": False, "Floor": True, "Lamp": False, "Room": True}


def test_a_detailed_object_is_judged_like_its_coarse_self_in_bounded_chunks(monkeypatch):
    coarse = _geometry()
    fine = _geometry(box_split=24)  # 6912 triangles on the same box
    # Small chunks force the chunked path through many products of at most this many heights.
    monkeypatch.setattr(mesh, "_PRODUCT_ENTRIES", 5000)
    expected = boundary_objects(coarse, _witnesses(coarse))
    assert np.array_equal(boundary_objects(fine, _witnesses(fine)), expected)


def test_every_witness_is_checked_not_only_the_sample():
    # 4000 witnesses on the lit side of the plane z = 0 and one below it, which the spread-out
    # sample (every third witness here) leaves out: the full pass must still find it.
    normals, offsets = np.array([[0.0, 0.0, 1.0]]), np.array([0.0])
    witnesses = np.column_stack([np.zeros(4001), np.zeros(4001), np.ones(4001)])
    assert mesh._all_on_lit_side(witnesses, normals, offsets, 1e-9)
    witnesses[1001, 2] = -1.0
    assert not mesh._all_on_lit_side(witnesses, normals, offsets, 1e-9)


def test_surface_keys_number_the_planes_of_each_object_in_order():
    geo = _geometry(box_split=4)
    keys = mesh.surface_keys(geo)
    box = geo.tri_object == geo.object_names.index("Box")
    # A box split into 16 triangles a face: six planes, each face's triangles sharing one key.
    assert len(np.unique(keys[box])) == 6
    normals = np.round(geo.normals[box], 6)
    for key in np.unique(keys[box]):
        assert len(np.unique(normals[keys[box] == key], axis=0)) == 1
    assert not set(keys[box]) & set(keys[~box])
    # The keys are 0..K-1 in the order of (object, normal, offset), as np.unique numbers rows.
    assert set(keys) == set(range(keys.max() + 1))
    order = [geo.tri_object[np.flatnonzero(keys == k)[0]] for k in range(keys.max() + 1)]
    assert order == sorted(order)
