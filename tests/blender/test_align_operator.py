"""Align to Photo (`dimred.align`) on the tiny room, its box proxy placed a few centimetres and
degrees off the photographed box: the operator moves it back and undo restores it; a proxy over
no object, or a fit that finds no plausible pose, reports and changes nothing; Align to Photo
before a removal leaves the box at the fitted pose."""
from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import bpy
import numpy as np
import pytest
from mathutils import Matrix

from tests.blender import tiny_scene

# The panorama's width: the tiny room's box is some thirty pixels across at 256.
WIDTH = 256


@pytest.fixture
def photo_room(registered, tmp_path: Path) -> Path:
    """The tiny room with a 256 x 128 panorama, saved, at draft quality; returns the .blend's path."""
    hdri = tmp_path / "room.exr"
    tiny_scene.write_exr(hdri, tiny_scene.synthetic_hdri(WIDTH, WIDTH // 2))
    tiny_scene.build_scene(hdri)
    blend = tmp_path / "room.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    bpy.context.scene.dimred.quality = "draft"
    return blend


def _pivot() -> np.ndarray:
    """The photographed box's bottom centre (the box mesh is modelled in world coordinates)."""
    lo, hi = np.array(tiny_scene.BOX)
    return np.array([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), lo[2]])


def _misplace(shift: tuple[float, float, float], turn_deg: float) -> Matrix:
    """Put the box `shift` metres and `turn_deg` about the vertical through its bottom centre off
    its photographed place and mark it there; returns its matrix_world."""
    pivot = Matrix.Translation(_pivot().tolist())
    matrix = (Matrix.Translation(shift) @ pivot @ Matrix.Rotation(math.radians(turn_deg), 4, 'Z')
              @ pivot.inverted())
    box = bpy.data.objects["Box"]
    box.matrix_world = matrix
    bpy.context.view_layer.update()
    bpy.context.scene.dimred.mark(box)
    return matrix


def _error(matrix: Matrix) -> tuple[float, float]:
    """(cm, degrees) between the box at `matrix` and the photographed box."""
    m = np.array(matrix)
    shift = np.linalg.norm(m[:3, :3] @ _pivot() + m[:3, 3] - _pivot()) * 100.0
    return float(shift), abs(math.degrees(math.atan2(m[1, 0], m[0, 0])))


def _align() -> set[str]:
    # As the UI calls it: a script's operator call pushes an undo step only when asked to.
    return bpy.ops.dimred.align('EXEC_DEFAULT', True)


def test_align_moves_a_misplaced_proxy_toward_the_photograph_and_undo_restores_it(photo_room):
    from diminished_reality.operators.support import pictures

    misplaced = _misplace((0.03, -0.01, 0.0), 3.0)
    shift_before, turn_before = _error(misplaced)
    bpy.ops.ed.undo_push(message="before alignment")

    assert _align() == {'FINISHED'}
    box = bpy.data.objects["Box"]
    shift_after, turn_after = _error(box.matrix_world)
    assert shift_after < 0.5 * shift_before and turn_after < 0.5 * turn_before, (shift_after, turn_after)
    settings = bpy.context.scene.dimred
    # Where it stood when marked moved with it: a later move by hand is measured from the fit.
    np.testing.assert_allclose(np.array(settings.marked_placement()), np.array(box.matrix_world), atol=1e-6)
    fit = json.loads(settings.photo_fit)
    assert fit["object"] == "Box" and fit["alignment"]["applied"]
    assert 0.5 < fit["segmentation"]["agreement"] <= 1.0
    assert pictures.DIAGNOSTICS_IMAGE in bpy.data.images

    bpy.ops.ed.undo()
    assert bpy.data.objects["Box"].matrix_world == misplaced


def test_a_proxy_over_no_object_reports_an_error_and_changes_nothing(photo_room):
    from diminished_reality.operators.support import pictures

    far = _misplace((0.0, 1.6, 1.2), 0.0)  # in the air before the bare wall
    settings = bpy.context.scene.dimred
    marked = settings.marked_placement()

    with pytest.raises(RuntimeError, match="does not lie over what the photograph shows") as refused:
        _align()

    assert len(str(refused.value).strip().splitlines()) == 1
    assert bpy.data.objects["Box"].matrix_world == far
    assert settings.marked_placement() == marked and settings.photo_fit == ""
    assert pictures.DIAGNOSTICS_IMAGE not in bpy.data.images


def test_a_fit_without_a_plausible_pose_warns_and_leaves_the_proxy(photo_room, extension, monkeypatch):
    from diminished_reality.addon import pipeline

    misplaced = _misplace((0.03, -0.01, 0.0), 3.0)
    real = pipeline.align_to_photo
    monkeypatch.setattr(pipeline, "align_to_photo", lambda *args, **kwargs: dataclasses.replace(
        real(*args, **kwargs), applied=False, message="alignment of 'Box' found no plausible pose"))

    assert _align() == {'CANCELLED'}

    assert bpy.data.objects["Box"].matrix_world == misplaced
    assert not json.loads(bpy.context.scene.dimred.photo_fit)["alignment"]["applied"]


def test_align_refuses_a_relocated_object_and_needs_a_panorama(photo_room):
    settings = bpy.context.scene.dimred
    assert not bpy.ops.dimred.align.poll()  # nothing marked
    settings.mark(bpy.data.objects["Box"])
    entry = settings.removals.add()
    entry.object_name, entry.kind = "Box", 'RELOCATE'
    entry.set_photographed_matrix(Matrix.Identity(4))
    with pytest.raises(RuntimeError, match="where its relocation put it"):
        _align()
    settings.removals.clear()

    bpy.context.scene.world = bpy.data.worlds.new("Plain")
    with pytest.raises(RuntimeError, match="shows no panorama"):
        _align()


def test_align_first_leaves_the_removed_box_at_the_fitted_pose(photo_room):
    settings = bpy.context.scene.dimred
    misplaced = _misplace((0.03, -0.01, 0.0), 3.0)
    settings.align_first = True

    assert bpy.ops.dimred.remove() == {'FINISHED'}

    report = json.loads(settings.last_report)
    assert report["alignment"]["applied"], report["alignment"]["message"]
    box = bpy.data.objects["Box"]
    np.testing.assert_allclose(np.array(box.matrix_world),
                               np.array(report["alignment"]["matrix"]) @ np.array(misplaced), atol=1e-6)
    assert _error(box.matrix_world)[0] < 0.5 * _error(misplaced)[0]
    assert json.loads(settings.photo_fit)["alignment"] == report["alignment"]


def test_align_first_relocates_from_the_fitted_pose(photo_room):
    settings = bpy.context.scene.dimred
    misplaced = _misplace((0.03, -0.01, 0.0), 3.0)
    settings.align_first = True

    assert bpy.ops.dimred.relocate(yaw=30.0, distance_scale=1.0) == {'FINISHED'}

    report = json.loads(settings.last_report)
    assert report["alignment"]["applied"], report["alignment"]["message"]
    fitted = np.array(report["alignment"]["matrix"]) @ np.array(misplaced)
    (entry,) = settings.removals
    np.testing.assert_allclose(np.array(entry.photographed_matrix()), fitted, atol=1e-6)
    np.testing.assert_allclose(np.array(bpy.data.objects["Box"].matrix_world),
                               np.array(report["relocation"]["matrix"]) @ fitted, atol=1e-6)
