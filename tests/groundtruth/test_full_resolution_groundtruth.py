"""A removal above the working width (1024x512 with `--working-width 512`: the light solved at
512x256, the object's window redone at full size) scores as well against its own Cycles truth as
a removal of the same scene rendered at 512x256, solved at its own size.

Both sizes of a scene are rendered at the same samples per pixel, so their pixels carry the same
Monte Carlo noise and the figures compare like with like: the lighting error ratio and the
object-and-shadow ratio are ratios of sums over the regions they cover, the hidden region's
brightness a ratio of means, the far damage a percentile of a per-pixel excess beyond a margin
that scales with the width, and the contact shadow (`ring_error`) is scored over the first 3 px
off the silhouette at each size, where a lighting change solved at a coarser resolution than
the panorama's shows blurred. No figure may be worse at 1024x512 than at 512x256 by more than
a few hundredths; better is fine. Each size of a scene goes once through the command line, as a
user runs it, at the default preset.
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from scenes import metrics as M
from scenes import spec as S
from scenes.images import read_exr
from scenes.render import REPO, render_pair

# A checker floor with two ceiling lamps. The same check passes on bright_lamp (a small lamp 10^3
# times brighter, right above a cylinder: the sharpest contact shadow of the registry), whose
# 2048x1024 pair takes about 5 minutes to render here: too long for every run of the suite.
# basic_box at 2048x1024 against 1024x512 (the default working width) passes too, and so did
# 1280x640 against 1024x512; the working width of 512 takes the same path at the same factor of
# 2 as 2048 against 1024, for an eighth of its render time.
WORKING_WIDTH = 512
FULL_WIDTH = 2 * WORKING_WIDTH
SCENES = ["basic_box"]
# 8 samples keep the 1024x512 pair near 50 seconds of CPU.
SAMPLES = 8
TOLERANCE = 0.03
# The fill's mean brightness moves by up to 0.04 with the synthesis seed alone (bright_lamp at
# 1024x512: 1.045 with seed 0, 1.083 with seed 1), so its bound leaves that much room.
MEAN_TOLERANCE = 0.05
# Pixel-scale detail at 8 samples is mostly the truth's noise, which the fill does not copy, and
# its share grows with the resolution: with the light solved and the region filled at 2048x1024
# the detail ratio was 0.77 (basic_box) and 0.74 (bright_lamp) of its 1024x512 value. A fill
# upsampled bilinearly from half the width keeps 0.2-0.3 of it.
DETAIL_SHARE = 0.7
RING_PX = 3


def _figures(name: str, width: int, out) -> dict[str, float]:
    """The removal's scores at `width` x width/2, solved at most `WORKING_WIDTH` wide, through the
    command line."""
    spec = S.get(name).with_render(width=width, height=width // 2, samples=SAMPLES)
    paths = render_pair(spec)
    proc = subprocess.run(
        [sys.executable, "-m", "addon.cli", "remove", str(paths["blend"]), "--object", spec.remove,
         "--out", str(out), "--quality", "balanced", "--working-width", str(WORKING_WIDTH)],
        cwd=REPO, capture_output=True, text=True, timeout=900,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    inp, edit, truth, mask = (read_exr(paths["input"]), read_exr(out / "edited.exr"), read_exr(paths["truth"]),
                              np.load(paths["mask"]))
    assert not np.isnan(edit).any() and not np.isnan(read_exr(out / "difference.exr")).any()
    report = json.loads((out / "report.json").read_text())
    assert report["working_resolution"] == [WORKING_WIDTH, WORKING_WIDTH // 2]
    assert report["parameters"]["working_width"] == WORKING_WIDTH
    region = M.lighting_region(inp, truth, mask)
    hidden = M.hidden_region_scores(inp, edit, truth, mask)
    return {
        "lighting_error_ratio": M.lighting_error_ratio(inp, edit, truth, mask, region),
        "far_damage": M.far_damage(inp, edit, truth, mask, region),
        "object_shadow_ratio": hidden["object_shadow_ratio"],
        "ring_error": M.ring_error(inp, edit, truth, mask, width_px=RING_PX),
        "mean_error": abs(hidden["mean_ratio"] - 1.0),
        "detail_ratio": hidden["detail_ratio"],
    }


@pytest.mark.slow
@pytest.mark.parametrize("name", SCENES)
def test_full_resolution_scores_as_the_working_resolution(name, tmp_path):
    working = _figures(name, WORKING_WIDTH, tmp_path / "working")
    full = _figures(name, FULL_WIDTH, tmp_path / "full")
    print(f"{name}: {WORKING_WIDTH}x{WORKING_WIDTH // 2} {working}\n{name}: {FULL_WIDTH}x{FULL_WIDTH // 2} {full}")
    allowed = {"mean_error": MEAN_TOLERANCE}
    worse = {k: (working[k], full[k]) for k in working
             if k != "detail_ratio" and full[k] > working[k] + allowed.get(k, TOLERANCE)}
    assert not worse, (f"{name}: worse at {FULL_WIDTH}x{FULL_WIDTH // 2} than at {WORKING_WIDTH}x{WORKING_WIDTH // 2} "
                       f"(working, full): {worse}")
    assert full["detail_ratio"] >= DETAIL_SHARE * working["detail_ratio"]


def test_ring_error_scores_the_pixels_beside_the_silhouette():
    rng = np.random.default_rng(0)
    truth = np.broadcast_to(0.5 + 0.05 * rng.random((16, 32, 1)), (16, 32, 3)).copy()
    mask = np.zeros((16, 32), bool)
    mask[6:10, 12:18] = True
    inp = truth.copy()
    inp[M.dilate(mask, 4)] *= 0.5
    assert M.ring_error(inp, inp, truth, mask, width_px=2) == pytest.approx(1.0)
    assert M.ring_error(inp, truth, truth, mask, width_px=2) == 0.0
    # Neither the hidden region's own error nor one beyond the ring is the ring's.
    ring = M.dilate(mask, 2) & ~mask
    wrong_elsewhere = truth.copy()
    wrong_elsewhere[~ring] = 9.0
    assert M.ring_error(inp, wrong_elsewhere, truth, mask, width_px=2) == 0.0
    halfway = truth.copy()
    halfway[ring] *= 0.75
    assert M.ring_error(inp, halfway, truth, mask, width_px=2) == pytest.approx(0.5)
    with pytest.raises(ValueError):
        M.ring_error(inp, inp, truth, np.ones((16, 32), bool), width_px=2)
