"""Each removal stage on its own, on the tiny room built from arrays (64x32, draft quality).

The room has a ceiling lamp right above the space between the probe and a 0.6 m box on a tiled
floor, so the box shadows the floor beside it: taking the box away must bring light back there.
Every stage returns a frozen result and leaves the results it was given as they were.
"""
from __future__ import annotations

import dataclasses
import hashlib

import numpy as np
import pytest

from addon.callbacks import NO_CALLBACKS, RunCallbacks
from addon.errors import Cancelled, DimredError
from addon.light.radiosity import LUMA, RHO_MAX
from addon.quality import params_for
from addon.removal import fill, finish, irradiance, solve_lighting
from addon.removal.compose import compose
from addon.removal.fill import fill_hidden, hidden_light, working_revealed
from addon.removal.first_order import first_order
from addon.removal.interpolation import interpolate
from addon.removal.lit_room import LitRoom
from addon.removal.local import local_light
from addon.removal.occlusion import occluders
from addon.removal.propagation import propagate_change
from addon.removal.room import solve_room
from addon.removal.target import prepare
from addon.removal.trace import trace
from addon.report import Report
from tests.engine import tiny_room

W, H = 64, 32
PARAMS = params_for("draft")


def _fingerprint(value: object) -> str:
    """A digest of every array reachable from a stage result (frozen dataclasses, tuples, lists)."""
    digest = hashlib.sha256()

    def walk(v: object) -> None:
        if isinstance(v, np.ndarray):
            digest.update(np.ascontiguousarray(v).tobytes())
        elif dataclasses.is_dataclass(v):
            for f in dataclasses.fields(v):
                walk(getattr(v, f.name))
        elif isinstance(v, (list, tuple)):
            for item in v:
                walk(item)

    walk(value)
    return digest.hexdigest()


@pytest.fixture(scope="module")
def stages():
    """Every stage's result, run in order as `removal.sequence` runs them, with the fingerprint
    each had when it was returned (taken before the next stage ran)."""
    scene = tiny_room.scene_data(W, H)
    rep = Report()
    out: dict[str, object] = {"scene": scene, "rep": rep}
    fingerprints: dict[str, str] = {}

    def keep(name: str, value: object) -> object:
        out[name] = value
        fingerprints[name] = _fingerprint(value)
        return value

    keep("scene", scene)
    geo, target = prepare(scene, "Box", (), PARAMS, rep)
    keep("geo", geo)
    keep("target", target)
    traced = keep("traced", trace(geo, target, W, H, fill=True, rep=rep))
    occlusion = keep("occlusion", occluders(geo, target, traced, rep))
    room = keep("room", solve_room(scene.hdri, geo, target, traced, occlusion, PARAMS, rep, NO_CALLBACKS))
    first = keep("first", first_order(room, target, occlusion, PARAMS, rep, NO_CALLBACKS))
    propagation = keep("propagation", propagate_change(first, occlusion, PARAMS, rep, NO_CALLBACKS))
    lit = keep("lit", LitRoom(geo=geo, target=target, occlusion=occlusion, room=first.room, db=propagation.db,
                              split=propagation.split))
    keep("local", local_light(lit, traced, PARAMS, rep, NO_CALLBACKS))
    solution = keep("solution", solve_lighting(scene.hdri, geo, target, traced, PARAMS, Report(), NO_CALLBACKS))
    out["finished"] = finish(solution, Report())
    out["fingerprints"] = fingerprints
    return out


def _floor_pixels(stages) -> np.ndarray:
    traced = stages["traced"]
    return traced.obj_h == stages["geo"].object_names.index("Floor")


def test_prepare_puts_the_probe_at_the_origin_and_bounds_the_box(stages):
    geo, target = stages["geo"], stages["target"]
    lo, hi = np.array(tiny_room.BOX[0]), np.array(tiny_room.BOX[1])
    centre = 0.5 * (lo + hi) - np.array(tiny_room.CENTER)
    assert np.allclose(target.centre, centre, atol=1e-6)
    assert target.radius == pytest.approx(0.5 * np.linalg.norm(hi - lo), rel=1e-6)
    assert 0 < target.fine_cell <= target.radius / PARAMS.fine_cells + 1e-12
    assert geo.object_names[target.index] == "Box" and target.planes == ()


def test_prepare_refuses_an_unknown_object_and_a_curved_plane():
    scene = tiny_room.scene_data(W, H)
    with pytest.raises(DimredError, match="no mesh object named 'Chair'"):
        prepare(scene, "Chair", (), PARAMS, Report())
    with pytest.raises(DimredError, match="'Room' is not planar"):
        prepare(scene, "Box", ("Room",), PARAMS, Report())


def test_trace_hides_the_box_with_its_silhouette_and_reveals_the_floor_behind_it(stages):
    traced, geo = stages["traced"], stages["geo"]
    box = geo.object_names.index("Box")
    on_box = traced.obj_h == box
    assert on_box.any() and traced.hidden_h[on_box].all()
    # The silhouette's mixed pixels are filled as well: more hidden pixels than box pixels.
    assert traced.hidden_h.sum() > on_box.sum()
    behind = traced.behind
    assert traced.hidden_h[behind.revealed].all()
    revealed_objects = {geo.object_names[k] for k in np.unique(geo.tri_object[behind.tri])}
    assert "Floor" in revealed_objects and "Box" not in revealed_objects
    # Without filling (an insertion) nothing is hidden but the object, and nothing traced behind it.
    plain = trace(geo, stages["target"], W, H, fill=False, rep=Report())
    assert plain.hidden_h.sum() == on_box.sum() and len(plain.behind.revealed) == 0


def test_the_room_shell_blocks_nothing_and_the_box_is_the_removed_occluder(stages):
    occlusion = stages["occlusion"]
    # The floor and the walls bound the room; the lamp hangs below the ceiling and may block.
    assert not {"Floor", "Room", "Box"} & set(stages["rep"].info["occluder_objects"])
    probe = np.zeros((1, 3))
    through_box = stages["target"].centre[None] * 2.0
    assert occlusion.removed.blocked(probe, through_box).all()


def test_the_room_finds_the_lamp_and_bounded_reflectances(stages):
    room, geo = stages["room"], stages["geo"]
    lamp = geo.object_names.index("Lamp")
    on_lamp = geo.tri_object[room.patches.patch_tri] == lamp
    assert room.emitter[on_lamp].all() and room.important[on_lamp].any()
    assert not room.emitter[~on_lamp].any()
    assert (room.rho >= 0).all() and (room.rho <= RHO_MAX).all()
    assert (room.senders.radiosity >= 0).all()
    assert room.t_with.shape == room.t_without.shape == (len(room.receivers.points), len(room.areas))
    # The box's own patches send nothing once it is gone.
    assert not room.t_without[:, room.patches.on_target].any()
    with pytest.raises(dataclasses.FrozenInstanceError):
        room.rho = room.rho * 0


def test_first_order_brings_light_back_to_the_floor_the_box_shadowed(stages):
    first, geo = stages["first"], stages["geo"]
    floor = geo.tri_object[first.room.patches.patch_tri] == geo.object_names.index("Floor")
    gain = first.de[floor] @ LUMA
    assert gain.max() > 0 and (gain >= -1e-9).sum() >= 0.95 * len(gain)
    # Only floor patches near the box change; the far floor keeps its light.
    centre = first.room.patches.triangles.mean(axis=1)
    far = floor & (np.linalg.norm(centre - stages["target"].centre, axis=1) > 2.5)
    assert np.abs(first.de[far] @ LUMA).max() < 0.05 * gain.max()


def test_propagation_adds_bounces_to_the_first_change(stages):
    first, propagation = stages["first"], stages["propagation"]
    assert stages["rep"].info["bounces"] >= 1
    db1 = first.room.rho * first.de
    db1[first.room.senders.on_removed | first.room.emitter] = 0.0
    # The walls and ceiling are lit by the brighter floor too: the total change exceeds the first bounce.
    assert (propagation.db @ LUMA * first.room.areas).sum() > (db1 @ LUMA * first.room.areas).sum()
    assert propagation.split.t_with is not None and propagation.split.t_without is not None


def test_local_light_brightens_the_shadowed_floor_pixels_and_leaves_e_positive(stages):
    local, traced = stages["local"], stages["traced"]
    floor = _floor_pixels(stages) & ~traced.hidden_h
    assert (local.e_h[floor] @ LUMA > 0).all()
    assert (local.de_h[floor] @ LUMA).max() > 0.1 * np.median(local.e_h[floor] @ LUMA)
    assert stages["rep"].info["exact_pairs"] > 0


def test_the_fine_lattice_is_coarser_far_from_the_object_and_agrees_with_the_fine_one_there(stages):
    lit, traced, target = stages["lit"], stages["traced"], stages["target"]
    floor = np.flatnonzero(_floor_pixels(stages) & ~traced.hidden_h)
    distance = np.linalg.norm(traced.points_h[floor] - target.centre, axis=1) / target.radius
    far = floor[(distance > irradiance.FAR_RADII) & (distance < 3.0)]
    tri, bary = traced.tri_h[far], traced.hits.bary.reshape(-1, 2)[traced.hp[far]]
    graded = irradiance.fine_light(lit, tri, bary, NO_CALLBACKS)
    # With a radius ten times larger every point is near: the fine lattice everywhere.
    uniform = irradiance.fine_light(dataclasses.replace(lit, target=dataclasses.replace(
        target, radius=target.radius * 10.0)), tri, bary, NO_CALLBACKS)
    assert len(graded.t_with) < len(uniform.t_with)
    e_graded = interpolate(graded.e, graded.corners, graded.weights) @ LUMA
    e_uniform = interpolate(uniform.e, uniform.corners, uniform.weights) @ LUMA
    # The lattices' own E (before the lamp's exact shadows replace its share per pixel).
    off = np.abs(e_graded / e_uniform - 1.0)
    assert off.mean() < 0.01 and off.max() < 0.05


def test_compose_changes_only_pixels_that_keep_their_surface(stages):
    solution = stages["solution"]
    d_h = compose(solution, Report())
    traced = solution.traced
    assert np.isfinite(d_h).all()
    assert not d_h[traced.hidden_h].any() and not d_h[solution.room.pixels.emitter_h].any()
    radiance = traced.panorama_rows(solution.hdri)
    assert (radiance + d_h >= 0).all()
    assert (d_h[_floor_pixels(stages) & ~traced.hidden_h] @ LUMA).max() > 0


def test_fill_gives_the_revealed_floor_positive_light_and_shows_its_progress(stages):
    solution = stages["solution"]
    shown: list[np.ndarray] = []
    revealed_pixels = working_revealed(solution)
    light = hidden_light(solution, revealed_pixels, NO_CALLBACKS)
    change, _ = fill_hidden(solution, revealed_pixels, light, Report(), NO_CALLBACKS, shown.append)
    revealed = solution.traced.behind.revealed
    assert change.shape == (len(revealed), 3) and np.isfinite(change).all()
    filled = solution.traced.panorama_rows(solution.hdri)[revealed] + change
    assert (filled >= 0).all() and (filled @ LUMA).mean() > 0
    assert len(shown) >= 2 and np.array_equal(shown[-1], change)


def test_planes_filled_side_by_side_give_what_they_give_one_after_the_other(stages, monkeypatch):
    solution = stages["solution"]
    revealed_pixels = working_revealed(solution)
    light = hidden_light(solution, revealed_pixels, NO_CALLBACKS)
    planes = fill.hidden_planes(solution.geo, solution.target.surface_key, revealed_pixels.tri,
                                revealed_pixels.points)

    def halves(*args):
        """Each plane as two, its points split in half: two fills of one surface at least."""
        return [(sel[part], dataclasses.replace(plane, points=plane.points[part]))
                for sel, plane in planes for part in np.array_split(np.arange(len(sel)), 2)]

    monkeypatch.setattr(fill, "hidden_planes", halves)
    side_by_side, reported = Report(), Report()
    together = fill.fill_hidden(solution, revealed_pixels, light, side_by_side, NO_CALLBACKS)
    in_turn = fill.fill_hidden(solution, revealed_pixels, light, reported, NO_CALLBACKS, lambda change: None)
    assert len(side_by_side.info["filled_surfaces"]) >= 2
    np.testing.assert_array_equal(together[0], in_turn[0])
    strip = [{k: v for k, v in s.items() if k != "seconds"} for s in side_by_side.info["filled_surfaces"]]
    assert strip == [{k: v for k, v in s.items() if k != "seconds"} for s in reported.info["filled_surfaces"]]


@pytest.mark.parametrize(("width", "structure", "tiling"), [(64, True, False), (128, True, True), (128, False, False)])
def test_how_each_fill_was_made_is_marked_for_the_seam(width, structure, tiling):
    # at 128x64 the tiles recur often enough around the box to be continued as a tiling, at
    # 64x32 the floor is synthesised per pixel; the room's walls are continued along their columns
    params = dataclasses.replace(PARAMS, synth_structure=structure)
    scene = tiny_room.scene_data(width, width // 2)
    geo, target = prepare(scene, "Box", (), params, Report())
    traced = trace(geo, target, width, width // 2, fill=True, rep=Report())
    solution = solve_lighting(scene.hdri, geo, target, traced, params, Report(), NO_CALLBACKS)
    revealed = working_revealed(solution)
    rep = Report()
    filled = fill.filled_reflectance(solution, revealed, rep, NO_CALLBACKS)
    surfaces = {s["surface"]: s for s in rep.info["filled_surfaces"]}
    assert (surfaces["Floor"]["structured_cells"] > 0) == tiling and surfaces["Floor"]["exemplar"] != "wall columns"
    assert surfaces["Room"]["exemplar"] == "wall columns"
    shows = np.array(geo.object_names)[geo.tri_object[revealed.tri]]
    assert (shows == "Floor").any() and (shows == "Room").any()
    assert np.array_equal(filled.continued, np.isin(shows, ["Floor", "Room"] if tiling else ["Room"]))
    # where the structure stage searched the floor for repeats and found none, the fill says so
    assert np.array_equal(filled.unrepeated, (shows == "Floor") & structure & (not tiling))


def test_finish_adds_the_difference_to_the_panorama_and_masks_the_object(stages):
    solution, result = stages["solution"], stages["finished"]
    assert result.difference.shape == solution.hdri.shape and result.difference.dtype == np.float32
    assert np.array_equal(result.edited, (solution.hdri + result.difference).astype(np.float32))
    assert np.array_equal(result.hidden_mask, solution.traced.hidden_map)
    untouched = ~np.isin(np.arange(W * H), solution.traced.hp)
    assert not result.difference.reshape(-1, 3)[untouched].any()


def test_no_stage_changes_what_it_was_given(stages):
    # The fixture ran every stage after these results were returned, and finish after them all.
    for name, before in stages["fingerprints"].items():
        assert _fingerprint(stages[name]) == before, f"a later stage changed the result of '{name}'"


def test_a_cancel_stops_the_lighting_between_stages():
    scene = tiny_room.scene_data(W, H)
    rep = Report()
    geo, target = prepare(scene, "Box", (), PARAMS, rep)
    traced = trace(geo, target, W, H, fill=True, rep=rep)
    with pytest.raises(Cancelled):
        solve_lighting(scene.hdri, geo, target, traced, PARAMS, rep, RunCallbacks(cancel=lambda: True))
    assert not issubclass(Cancelled, DimredError)


def test_the_shadow_lift_multiplies_the_edited_radiance_per_channel_where_it_is_above_one():
    radiance = np.full((2, 3, 3), 0.5, np.float32)
    change = np.full((2, 3, 3), 0.1, np.float32)
    lift = np.ones((2, 3, 3), np.float32)
    lift[0, 1] = (2.0, 1.5, 1.0)
    got = fill.lifted(radiance, change, lift)
    np.testing.assert_allclose(got[0, 1], (0.5 + 0.1) * np.array([2.0, 1.5, 1.0]) - 0.5, rtol=1e-6)
    unlifted = np.ones((2, 3), bool)
    unlifted[0, 1] = False
    np.testing.assert_array_equal(got[unlifted], change[unlifted])
    assert fill.lifted(radiance, change, None) is change
