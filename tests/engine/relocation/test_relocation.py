"""Relocation in the engine (removal at the old place plus insertion at the new one, the move
limited to what the panorama can show): removal and insertion undo each other, the object
shows at its new place, and placements that break the constraint are refused."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from addon.errors import DimredError
from addon.geometry import latlong
from addon.light.radiosity import LUMA
from addon.pipeline import relocate_object, remove_object
from addon.relocation.fixedview import Move
from addon.relocation.placement import place
from tests.engine import tiny_room


@pytest.fixture(scope="module")
def tiny():
    return tiny_room.scene_data(128, 64)


def _box_pixels(scene, lo, hi, matrix: np.ndarray | None = None) -> np.ndarray:
    """(H, W) pixels whose ray from the probe enters the box lo..hi, moved by the 4x4 `matrix`
    if given."""
    h, w = scene.hdri.shape[:2]
    inverse = np.eye(4) if matrix is None else np.linalg.inv(matrix)
    d = latlong.pixel_directions(w, h) @ inverse[:3, :3].T
    return np.isfinite(tiny_room._ray_box(inverse[:3, :3] @ scene.center + inverse[:3, 3], d, lo, hi))


def test_moving_nowhere_gives_back_the_photograph(tiny):
    """Insertion is removal run backwards: removed and put back in place, the panorama returns
    to what it was, up to a small share of the removal's own change."""
    removal = remove_object(tiny, "Box", quality="draft")
    back = relocate_object(tiny, "Box", Move(0.0, 1.0), quality="draft")
    assert np.isfinite(back.difference).all()
    y_back, y_removal = np.abs(back.difference) @ LUMA, np.abs(removal.difference) @ LUMA
    assert y_back.sum() <= 0.15 * y_removal.sum()
    assert back.report["relocation"]["elevation_change"] == 0.0


def test_the_object_shows_at_its_new_place(tiny):
    result = relocate_object(tiny, "Box", Move(-90.0, 1.0), quality="draft")
    rel = result.report["relocation"]
    assert rel["support"] == ["Floor"] and rel["object_pixels"] > 0 and rel["insertion_passes"] == 2
    assert np.isfinite(result.edited).all() and (result.edited >= 0).all()
    lo, hi = np.array(tiny_room.BOX[0]), np.array(tiny_room.BOX[1])
    old = _box_pixels(tiny, lo, hi)
    # The box turned by -90 degrees about the probe's axis: (x, y) -> (y, -x).
    new = _box_pixels(tiny, (lo[1], -hi[0], lo[2]), (hi[1], -lo[0], hi[2]))
    core_old, core_new = old & ~latlong.dilate(~old, 1), new & ~latlong.dilate(~new, 1)
    redness = result.edited[..., 0] / np.maximum(result.edited.sum(axis=2), 1e-9)
    photo_redness = tiny.hdri[..., 0] / np.maximum(tiny.hdri.sum(axis=2), 1e-9)
    assert photo_redness[core_old].mean() > 0.6
    assert redness[core_new].mean() > 0.6 > redness[core_old].mean() + 0.15
    assert result.hidden_mask[core_old].all() and result.hidden_mask[core_new].all()
    assert result.report["seconds"]["total"] > 0 and "removal_synthesis" in result.report["seconds"]


def _floating(scene, lift: float):
    rows = np.asarray(scene.tri_object) == scene.object_names.index("Box")
    tris = scene.triangles.copy()
    tris[rows, :, 2] += lift
    return replace(scene, triangles=tris)


def _with_cabinet(scene):
    """A second object standing where a 90-degree turn puts the box."""
    return _with_object(scene, "Cabinet", tiny_room.box_triangles((-0.3, 0.6, 0.0), (0.3, 1.4, 0.9)))


def _with_object(scene, name: str, triangles: np.ndarray):
    """`scene` with one more object made of `triangles`."""
    return replace(scene, triangles=np.concatenate([scene.triangles, triangles]),
                   tri_object=np.concatenate([scene.tri_object, np.full(len(triangles), len(scene.object_names))]),
                   object_names=[*scene.object_names, name])


@pytest.mark.parametrize("case, move, expected", [
    ("floating", Move(10.0, 1.0), "'Box' does not stand on a surface"),
    ("through the wall", Move(0.0, 1.8), "would not stand on its support plane"),
    ("into another object", Move(90.0, 1.0), "would cut through 'Cabinet'"),
    ("no distance", Move(30.0, 0.0), "positive number"),
])
def test_placements_that_break_the_constraint_are_refused(tiny, case, move, expected):
    scene = {"floating": _floating(tiny, 0.2), "into another object": _with_cabinet(tiny)}.get(case, tiny)
    before = scene.triangles.copy()
    with pytest.raises(DimredError, match=expected):
        place(scene, scene.object_names.index("Box"), move)
    with pytest.raises(DimredError, match=expected):
        relocate_object(scene, "Box", move, quality="draft")
    np.testing.assert_array_equal(scene.triangles, before)


def test_a_move_along_the_floor_is_allowed(tiny):
    placement = place(tiny, tiny.object_names.index("Box"), Move(135.0, 0.8))
    assert placement.support == ["Floor"]
    assert placement.elevation_change < 0.0  # nearer: seen more from above


@pytest.mark.parametrize("offset", [-0.008, 0.008])
def test_a_proxy_sunk_into_the_floor_or_floating_a_little_still_stands_on_it(tiny, offset):
    """Hand-modelled proxies are rarely exact: within 2 % of the object's height counts as standing."""
    scene = _floating(tiny, offset)
    assert place(scene, scene.object_names.index("Box"), Move(45.0, 1.1)).support == ["Floor"]


def _visible_floor(scene, occluders) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) pixels whose ray from the probe reaches the room's floor past the boxes
    `occluders` ((lo, hi) pairs), and (H, W, 3) the floor points the rays reach."""
    h, w = scene.hdri.shape[:2]
    d = latlong.pixel_directions(w, h)
    c = np.asarray(scene.center)
    with np.errstate(divide="ignore"):
        t = np.where(d[..., 2] < 0, -c[2] / d[..., 2], np.inf)
    points = c + d * np.where(np.isfinite(t), t, 0.0)[..., None]
    lo, hi = tiny_room.ROOM
    seen = np.isfinite(t) & np.all((points[..., :2] > lo[:2]) & (points[..., :2] < hi[:2]), axis=-1)
    for box_lo, box_hi in occluders:
        seen &= ~(tiny_room._ray_box(c, d, box_lo, box_hi) < t)
    return seen, points


def test_a_new_place_hidden_from_the_probe_still_casts_its_shadow(tiny):
    """Behind a tall cabinet the box shows no pixel; the floor beside it, which the cabinet
    leaves in view, still gets darker where the box now takes light away, and nowhere else."""
    cabinet = ((-0.5, -0.22, 0.0), (-0.4, 0.22, 1.6))  # just wide enough to hide the box from the probe
    scene = _with_object(tiny, "Cabinet", tiny_room.box_triangles(*cabinet))
    result = relocate_object(scene, "Box", Move(180.0, 1.0), quality="draft")
    assert result.report["relocation"]["object_pixels"] == 0
    assert any("hidden from the probe" in w for w in result.report["warnings"])
    assert np.isfinite(result.difference).all()

    # Relocation is removal at the old place plus insertion at the new one: without the removal's
    # own change, what is left is the insertion's, the box's shadow and reflected light.
    removal = remove_object(scene, "Box", quality="draft")
    darkening = ((result.difference - removal.difference) @ LUMA) / np.maximum(tiny.hdri @ LUMA, 1e-6)
    # The box turned by 180 degrees about the probe's axis: (x, y) -> (-x, -y).
    lo, hi = np.array(tiny_room.BOX[0]), np.array(tiny_room.BOX[1])
    new_lo, new_hi = (-hi[0], -hi[1], lo[2]), (-lo[0], -lo[1], hi[2])
    floor, points = _visible_floor(tiny, [cabinet, (new_lo, new_hi)])
    outside = np.maximum(np.maximum(np.asarray(new_lo[:2]) - points[..., :2], points[..., :2] - new_hi[:2]), 0.0)
    distance = np.linalg.norm(outside, axis=-1)  # from the box's footprint
    beside, far = floor & (distance < 0.3), floor & (distance > 1.0)
    assert beside.sum() >= 40 and far.sum() >= 500
    assert darkening[beside].mean() < -0.015, f"beside the new place {darkening[beside].mean():+.4f}"
    assert abs(darkening[far].mean()) < 0.005, f"far from it {darkening[far].mean():+.4f}"


def test_the_support_is_a_plane_not_an_object(tiny):
    """A floor modelled in pieces or a rug lying on it holds the object as well at the same height."""
    half = -1.0  # the floor's x < half becomes an object of its own, with a rug on it
    floor = tiny.object_names.index("Floor")

    def quad(x0, x1, y0, y1, z):
        return np.array([[[x0, y0, z], [x1, y0, z], [x1, y1, z]], [[x0, y0, z], [x1, y1, z], [x0, y1, z]]])

    keep = tiny.tri_object != floor
    lo, hi = tiny_room.ROOM[0], tiny_room.ROOM[1]
    parts = [quad(half, hi[0], lo[1], hi[1], 0.0), quad(lo[0], half, lo[1], hi[1], 0.0),
             quad(-1.6, -0.4, -0.6, 0.6, 0.002)]
    names = [*tiny.object_names, "FloorWest", "Rug"]
    ids = [floor, len(tiny.object_names), len(tiny.object_names) + 1]
    scene = replace(tiny, triangles=np.concatenate([tiny.triangles[keep], *parts]),
                    tri_object=np.concatenate([tiny.tri_object[keep], *[np.full(2, k) for k in ids]]),
                    object_names=names)
    placement = place(scene, scene.object_names.index("Box"), Move(180.0, 1.0))
    assert set(placement.support) <= {"Floor", "FloorWest", "Rug"} and "Floor" not in placement.support


def test_the_number_of_insertion_passes_is_a_parameter(tiny):
    one = relocate_object(tiny, "Box", Move(-90.0, 1.0), quality="draft", insertion_passes=1)
    three = relocate_object(tiny, "Box", Move(-90.0, 1.0), quality="draft", insertion_passes=3)
    assert (one.report["relocation"]["insertion_passes"], three.report["relocation"]["insertion_passes"]) == (1, 3)
    assert {"removal_local", "insertion_local", "insertion", "total"} <= set(three.report["seconds"])
    # More passes move the result towards the same fixed point, not elsewhere.
    change = np.abs(three.difference - one.difference).sum()
    assert change < 0.5 * np.abs(three.difference).sum()
    with pytest.raises(DimredError, match="insertion_passes must be at least 1"):
        relocate_object(tiny, "Box", Move(-90.0, 1.0), quality="draft", insertion_passes=0)


MOVE = Move(-40.0, 1.2)


@pytest.fixture(scope="module")
def unturned(tiny):
    return relocate_object(tiny, "Box", MOVE, quality="draft")


def _placed_columns(scene, matrix: np.ndarray, columns: int) -> np.ndarray:
    """The panorama columns the box moved by `matrix` covers, turned by `columns`."""
    hit = _box_pixels(scene, *tiny_room.BOX, matrix)
    return np.unique((np.nonzero(hit.any(axis=0))[0] + columns) % hit.shape[1])


@pytest.mark.parametrize("columns, across_the_seam", [(32, None), (64, "old place"), (50, "new place")])
def test_a_move_in_a_turned_world_and_across_the_seam_is_the_same_move(tiny, unturned, columns, across_the_seam):
    """The world's texture rotation and the panorama's seam are conventions of the photograph,
    not of the room: the room photographed turned by whole pixel columns gives the same move's
    difference image, turned by as much (the fill up to its synthesis's choices)."""
    turned = relocate_object(tiny_room.turned(tiny, columns), "Box", MOVE, quality="draft")
    w = tiny.hdri.shape[1]
    at = {"old place": np.eye(4), "new place": np.array(unturned.report["relocation"]["matrix"])}
    if across_the_seam is not None:
        covered = _placed_columns(tiny, at[across_the_seam], columns)
        assert {0, w - 1} <= set(covered.tolist())
    assert turned.report["relocation"] == unturned.report["relocation"]
    hidden = np.roll(unturned.hidden_mask, columns, axis=1)
    assert np.array_equal(turned.hidden_mask, hidden)
    expected = np.roll(unturned.difference, columns, axis=1)
    error, size = np.abs(turned.difference - expected) @ LUMA, np.abs(expected) @ LUMA
    # The light: the same to rounding, at most 1e-3 a pixel. In all 2.5 % (0.3-0.5 % with one
    # fine lattice near the object): the insertion's passes read back light from the coarser
    # lattice beyond 1.6 object radii, whose vertices the turned room's rounding moves a hair.
    assert error[~hidden].sum() <= 0.03 * size[~hidden].sum() and error[~hidden].max() <= 1e-3
    # The fill: its brightness (a pixel's choice of source flips with the rounding: 4-12 % apart
    # as the fine lattice's reach is varied from 1.6 to 2.5 object radii).
    assert (turned.difference @ LUMA)[hidden].mean() == pytest.approx((expected @ LUMA)[hidden].mean(), rel=0.15)


def test_above_the_working_resolution_the_move_is_solved_on_the_working_copy_and_the_removal_at_full_size(tiny):
    # The proxy's silhouette is filled as modelled (no segmentation): the images compared are
    # the same pixels at two sizes, and this is about the paths, not the segmentation's.
    options = {"quality": "draft", "segmentation_band": 0.0}
    small = relocate_object(tiny, "Box", Move(-90.0, 1.0), **options)
    big_scene = replace(tiny, hdri=np.repeat(np.repeat(tiny.hdri, 2, axis=0), 2, axis=1))
    big = relocate_object(big_scene, "Box", Move(-90.0, 1.0), working_width=128, **options)
    assert big.report["working_resolution"] == [128, 64]
    assert big.difference.shape == (128, 256, 3) and big.hidden_mask.shape == (128, 256)
    # The working copy is the small panorama itself: its change, interpolated over 2 x 2 pixels.
    pooled = big.difference.reshape(64, 2, 128, 2, 3).mean(axis=(1, 3))
    assert np.abs(pooled - small.difference).mean() < 0.2 * np.abs(small.difference).mean()
    assert np.array_equal(big.hidden_mask[::2, ::2], small.hidden_mask)
    # The old place is filled at full resolution: the removal's own mask and fill are there.
    removal = remove_object(big_scene, "Box", working_width=128, **options)
    old = removal.hidden_mask
    assert big.hidden_mask[old].all()
    assert np.abs(big.difference[old] - removal.difference[old]).mean() < 0.2 * np.abs(removal.difference[old]).mean()
