"""Relocation checked against physics: a Cycles render of each scene with the object at its old
place (the input) and one with it at the moved place (the truth), as the user runs it through
the command line (`python -m addon.cli relocate ...`).

The score is taken over the union of both object regions and both shadows (`relocation_region`:
the lighting each placement changes against the render without the object): the error of the
edit over that of the unedited input, at most 40 % (the edit must remove most of what the move
changes, though the moved object's appearance is carried from one view only), with every pixel finite
and nothing damaged far from both places. The scenes differ in room, lamps, object kind and
colour, and the move's direction and size.
"""
from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import dataclass

import numpy as np
import pytest

from scenes import metrics as M
from scenes import spec as S
from scenes.images import read_exr
from scenes.render import REPO, load_pair, render_pair

BOUND = 0.4
FAR_DAMAGE = 0.08
# red_box, moved by 25 degrees and 0.8 of its distance, is checked with its colour below. A move
# in a turned world (the rotated_world scene) or across the panorama's seam (seam) is the same
# move as in basic_box, turned: `tests/engine/relocation/test_relocation.py` holds the engine to
# that to rounding, so their renders (in the suite until the 15 minutes of CI ran out) left it.
CASES = [("basic_box", 40.0, 1.3), ("stool", 40.0, 1.3), ("wall_contact", -40.0, 1.3), ("second_object", -40.0, 1.3),
         ("bright_lamp", 40.0, 1.3), ("nadir", 40.0, 1.3)]


def _relocate(tmp_path, blend, name: str, *arguments: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "addon.cli", "relocate", str(blend), "--object", name, "--out", str(tmp_path / "out"),
         *arguments],
        cwd=REPO, capture_output=True, text=True, timeout=900,
    )


@dataclass
class Relocated:
    """The renders with the object at its old place (`input`), without it (`empty`) and at the
    new place (`truth`), the two object masks, and the command line's edit and report."""

    input: np.ndarray
    empty: np.ndarray
    truth: np.ndarray
    old_mask: np.ndarray
    new_mask: np.ndarray
    edit: np.ndarray
    report: dict


def _relocated(spec: S.SceneSpec, yaw: float, scale: float, tmp_path) -> Relocated:
    """Relocate through the command line as a user does; every output pixel finite."""
    inp, empty, old_mask = load_pair(spec)
    truth, _, new_mask = load_pair(S.relocated(spec, yaw, scale))
    blend = render_pair(spec)["blend"]
    proc = _relocate(tmp_path, blend, spec.remove, "--yaw", str(yaw), "--distance-scale", str(scale))
    assert proc.returncode == 0, proc.stderr[-2000:]
    out = tmp_path / "out"
    edit, diff = read_exr(out / "edited.exr"), read_exr(out / "difference.exr")
    assert np.isfinite(edit).all() and np.isfinite(diff).all()
    return Relocated(inp, empty, truth, old_mask, new_mask, edit, json.loads((out / "report.json").read_text()))


def _assert_matches_the_render(name: str, yaw: float, scale: float, r: Relocated) -> float:
    """Assert the bounds every move keeps; return the error ratio."""
    region = M.relocation_region(r.input, r.truth, r.empty, r.old_mask, r.new_mask)
    ratio = M.relocation_error_ratio(r.input, r.edit, r.truth, region)
    far = M.far_damage(r.input, r.edit, r.truth, r.old_mask | r.new_mask, region=region)
    rel = r.report["relocation"]
    print(f"{name} yaw {yaw} x{scale}: error {ratio:.3f} of the input's over {int(region.sum())} px, far damage "
          f"{far:.3f}, elevation {rel['elevation_change']:+.1f} deg, {r.report['seconds']['total']:.1f} s")
    assert ratio <= BOUND
    assert far <= FAR_DAMAGE
    assert rel["yaw"] == yaw and rel["distance_scale"] == scale and rel["support"] == ["Floor"]
    return ratio


@pytest.mark.slow
@pytest.mark.parametrize("name, yaw, scale", CASES)
def test_relocation_matches_the_render_at_the_new_place(name, yaw, scale, tmp_path):
    _assert_matches_the_render(name, yaw, scale, _relocated(S.get(name), yaw, scale, tmp_path))


@pytest.mark.slow
@pytest.mark.parametrize("name, yaw, scale, expected", [
    ("red_box", -40.0, 1.3, "would not stand on its support plane"),
    ("second_object", 40.0, 1.3, "would cut through 'Cabinet'"),
    ("zenith", 30.0, 1.0, "does not stand on a surface"),
    ("basic_box", 40.0, 0.0, "distance factor must be a positive number"),
])
def test_a_move_the_constraint_forbids_is_refused(name, yaw, scale, expected, tmp_path):
    spec = S.get(name)
    blend = render_pair(spec)["blend"]
    before = blend.read_bytes()
    proc = _relocate(tmp_path, blend, spec.remove, "--yaw", str(yaw), "--distance-scale", str(scale))
    lines = [line for line in proc.stderr.splitlines() if line.startswith("dimred:")]
    assert proc.returncode == 2 and len(lines) == 1 and expected in lines[0], proc.stderr[-2000:]
    assert not (tmp_path / "out").exists()
    assert blend.read_bytes() == before


@pytest.mark.slow
def test_an_object_moved_out_of_a_shadow_is_lit_at_its_new_place(tmp_path):
    """Thesis 5.2: the photograph shows the box in a cabinet's shadow; moved into the lamp's
    light its carried appearance must brighten as much as the render says, not keep the shadow.
    The box is lit indirectly there, so the renders take 128 samples: at 64 their noise alone
    is a third of the input's error; the edit's error is 0.37 of the input's at 128, 0.32 at
    256 (which takes twice the render time)."""
    r = _relocated(S.get("shadowed_box").with_render(samples=128), 40.0, 1.3, tmp_path)
    ratio = _assert_matches_the_render("shadowed_box", 40.0, 1.3, r)
    inp, truth, old_mask, new_mask, edit = r.input, r.truth, r.old_mask, r.new_mask, r.edit
    core_old, core_new = (m & ~M.dilate(~m, 1) for m in (old_mask, new_mask))
    pairs = ((inp, core_old), (edit, core_new), (truth, core_new))
    y_photo, y_edit, y_truth = (M.luminance(a)[c].mean() for a, c in pairs)
    print(f"shadowed_box: error {ratio:.3f}; the box's mean luminance: photographed {y_photo:.4f}, "
          f"moved {y_edit:.4f}, rendered there {y_truth:.4f}")
    assert y_photo < 0.85 * y_truth
    assert abs(y_edit / y_truth - 1.0) <= 0.1


@pytest.mark.slow
def test_a_red_box_moved_colours_the_floor_at_its_new_place(tmp_path):
    """The light the object reflects goes with it: around the red box's new place the floor's
    colour must match the render's (the room without the box lacks that red tint). The move
    must match the render at the new place as every other does."""
    r = _relocated(S.get("red_box"), 25.0, 0.8, tmp_path)
    _assert_matches_the_render("red_box", 25.0, 0.8, r)
    inp, empty, truth, old_mask, new_mask, edit = r.input, r.empty, r.truth, r.old_mask, r.new_mask, r.edit
    both = old_mask | new_mask
    around = M.dilate(new_mask, 12) & ~M.dilate(both, 2)
    without_box, _ = M.bleeding_error(empty, edit, truth, both, around)
    photographed, moved = M.bleeding_error(inp, edit, truth, both, around)
    print(f"red_box: colour error around the new place: room without the box {without_box:.4f}, "
          f"photograph {photographed:.4f}, relocated {moved:.4f}")
    assert moved <= 0.3 * without_box and moved <= 0.5 * photographed
