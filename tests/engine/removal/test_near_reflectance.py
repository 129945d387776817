"""The reflectance of the patches around the removed object read from their pixels, and the
room's change of light corrected for it (`removal.near_reflectance`), on the tiny room."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from addon.callbacks import NO_CALLBACKS
from addon.light.radiosity import LUMA
from addon.quality import params_for
from addon.removal.first_order import first_order
from addon.removal.lit_room import LitRoom
from addon.removal.local import local_light
from addon.removal.near_reflectance import corrected_near_object
from addon.removal.occlusion import occluders
from addon.removal.propagation import propagate_change
from addon.removal.room import solve_room
from addon.removal.target import prepare
from addon.removal.trace import trace
from addon.report import Report
from tests.engine import tiny_room

W, H = 128, 64
PARAMS = params_for("draft")
BRIGHTER = 1.5  # the floor within this reach of the box is painted this many times brighter
REACH = 0.9  # metres from the box's centre, on the floor


def _solved(hdri: np.ndarray) -> dict:
    scene = replace(tiny_room.scene_data(W, H), hdri=hdri)
    rep = Report()
    geo, target = prepare(scene, "Box", (), PARAMS, rep)
    traced = trace(geo, target, W, H, fill=True, rep=rep)
    occlusion = occluders(geo, target, traced, rep)
    room = solve_room(hdri, geo, target, traced, occlusion, PARAMS, rep, NO_CALLBACKS)
    first = first_order(room, target, occlusion, PARAMS, rep, NO_CALLBACKS)
    propagation = propagate_change(first, occlusion, PARAMS, rep, NO_CALLBACKS)
    lit = LitRoom(geo=geo, target=target, occlusion=occlusion, room=first.room, db=propagation.db,
                  split=propagation.split)
    local = local_light(lit, traced, PARAMS, rep, NO_CALLBACKS)
    given = [a.copy() for a in (lit.room.rho, lit.db, lit.split.db, local.e_h, local.de_h, first.de)]
    corrected, after = corrected_near_object(lit, first, traced, traced.panorama_rows(hdri), local, PARAMS, rep)
    return {"geo": geo, "target": target, "traced": traced, "first": first, "lit": lit, "local": local,
            "corrected": corrected, "after": after, "given": given}


@pytest.fixture(scope="module")
def rooms() -> dict:
    """The tiny room as painted, and with the floor around the box painted brighter (a lighter
    rug under it), each solved up to the corrected light."""
    plain = tiny_room.scene_data(W, H).hdri
    seen = _solved(plain)
    traced, geo, target = seen["traced"], seen["geo"], seen["target"]
    floor = traced.obj_h == geo.object_names.index("Floor")
    near = np.linalg.norm((traced.points_h - target.centre)[:, :2], axis=1) < REACH
    bright = plain.reshape(-1, 3).copy()
    bright[traced.hp[floor & near & ~traced.hidden_h]] *= BRIGHTER
    return {"plain": seen, "bright": _solved(bright.reshape(plain.shape))}


def _floor_patches(solved: dict) -> tuple[np.ndarray, np.ndarray]:
    """The floor's patches under the box that the probe does not see, and those far from it."""
    room, geo, target = solved["lit"].room, solved["geo"], solved["target"]
    floor = geo.tri_object[room.patches.patch_tri] == geo.object_names.index("Floor")
    distance = np.linalg.norm((room.patches.triangles.mean(axis=1) - target.centre)[:, :2], axis=1)
    under = np.intersect1d(np.flatnonzero(floor & ~room.visible & (distance < REACH)), solved["first"].refined)
    return under, np.flatnonzero(floor & room.visible & (distance > 2 * REACH))


def test_the_floor_hidden_under_the_box_takes_the_reflectance_of_the_floor_around_it(rooms):
    bright = rooms["bright"]
    under, far = _floor_patches(bright)
    assert len(under) and len(far)
    before = bright["lit"].room.rho @ LUMA
    after = bright["corrected"].room.rho @ LUMA
    # before: the floor's mean; after: the brighter floor around the box
    assert before[under].mean() == pytest.approx(before[far].mean(), rel=0.15)
    assert after[under].mean() == pytest.approx(BRIGHTER * before[far].mean(), rel=0.15)


def test_a_brighter_floor_around_the_box_brightens_the_room_more(rooms):
    # What the revealed floor and the relit floor reflect is carried to the whole room: the
    # ceiling's change of light grows with the floor's reflectance around the box.
    def ceiling_change(solved: dict, name: str) -> float:
        traced, geo = solved["traced"], solved["geo"]
        ceiling = traced.obj_h == geo.object_names.index("Room")
        ceiling &= traced.normals_h[:, 2] < -0.5
        light = solved[name]
        return float(((light.de_h @ LUMA) / (light.e_h @ LUMA))[ceiling].mean())

    plain, bright = rooms["plain"], rooms["bright"]
    gain_before = ceiling_change(bright, "local") - ceiling_change(plain, "local")
    gain_after = ceiling_change(bright, "after") - ceiling_change(plain, "after")
    assert gain_after > 1.3 * max(gain_before, 0.0)


def test_the_correction_changes_nothing_it_was_given(rooms):
    bright = rooms["bright"]
    lit, local, first = bright["lit"], bright["local"], bright["first"]
    now = (lit.room.rho, lit.db, lit.split.db, local.e_h, local.de_h, first.de)
    assert all(np.array_equal(a, b) for a, b in zip(bright["given"], now, strict=True))
    assert np.array_equal(bright["after"].e_h, local.e_h)
