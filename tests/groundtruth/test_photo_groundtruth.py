"""Removal on photo-textured rooms, checked against physics: floors projected from real
photographs (their grain, a rug, furniture feet and contact shadows printed on them), lit by a
window and ceiling lamps, rendered with and without the object (`scenes.spec.PHOTO_SPECS`).

Each scene goes through the command line as a user runs it (balanced) once, and each figure of
`scenes.metrics.clean_removal_scores` is held to the issue's bound in a test of its own. Where the
engine does not meet a bound yet, that test is marked xfail (strict) with the measured figure: it
turns into a failure the day the engine passes, and the mark is then taken off.
Renders are 256x128 at 32 samples (about 10 s of CPU a pair), cached.
"""
from __future__ import annotations

from collections.abc import Callable

import pytest
from test_removal_groundtruth import _remove

from scenes import metrics as M
from scenes import spec as S

SCENES = ["hotel_box", "hotel_walls", "apartment_chair", "workshop_box", "hotel_rug_box", "apartment_sun_box"]
SIZE = {"width": 256, "height": 128, "samples": 32}
BOUNDS = M.CLEAN_REMOVAL_BOUNDS  # figure: (lowest, highest) it may take
# (scene, figure): what the engine measured where it fails the bound (256x128). Of each total,
# the error left outside the object (the relit shadow and light, region A) alone is 0.241
# (hotel_box), 0.136 (hotel_walls) and 0.154 (workshop_box): no fill meets 0.2 there by itself.
# At 32 samples region A is mostly render noise: the truth's own change smoothed over 5x5 px
# leaves 0.22 of hotel_box's light error, over 9x9 px 0.33 (the engine 0.35).
FAILING: dict[tuple[str, str], str] = {
    # The wood between the rug and the desk chair, printed brighter where the box stands (0.57)
    # than the wood around it, is filled a fifth too dark: the brightest wood at the hole's
    # border is found in too few directions around it to count as its material (about half of
    # them, three quarters needed) and is left out of the exemplar, the darker wood and the
    # rug's stripes farther out are kept (the exemplar's mean 0.40, the border's 0.50).
    ("hotel_box", "total"): "measured 0.448",
    ("hotel_box", "mean_error"): "measured 0.181",
    # The plain wall behind the box, continued along its columns (`wall_columns`), carries a
    # little less of the render's noise than the synthesis did: 0.809 without the columns, and
    # with seeds 1 and 2 0.872 and 0.849 (0.882 and 0.864 without); the bound is a draw's edge.
    ("hotel_box", "detail"): "measured 0.796",
    # The walls are continued along their columns (`wall_columns`): the white wall and the dark
    # door come down through the hole to the proxy's floor line (mean error 0.095 -> 0.029).
    # The photograph projected on the proxy's wall shows the floor under the door (its door
    # stands farther back than the proxy's wall), so the continued door is dark where the truth
    # is floor-coloured, and its edges over the pale wall add more detail than the truth's.
    ("hotel_walls", "total"): "measured 0.442",
    ("hotel_walls", "detail"): "measured 1.28",
    ("hotel_walls", "bruise_share"): "measured 0.111",
    # The yellow floor line crosses the hole between the green floor and the brown one: it is
    # continued as a strip, each side synthesised from its own colour (`crossing`; structure
    # 0.956, mean error 0.023). Most of the total is the light error outside the object (0.154,
    # above). At this size the strip and the sides are synthesised from a few hundred cells of
    # their colour right beside the hole, whose copies add less of the photograph's fine detail
    # than copies from the whole floor did (0.91 before the strip); at 512x256 and 128 samples
    # the detail is 1.03 (bench_photo_groundtruth); at 512 and 1024, 16 and 64 samples, its
    # median 0.91 and the worst draw 0.75 (bench_photo_stability).
    ("workshop_box", "total"): "measured 0.294",
    ("workshop_box", "detail"): "measured 0.705",
    # The rug's striped band passes under the box between the bed's olive cover and the wood,
    # which read as one colour around the hole (their chromaticities within 0.04). Its texture
    # tells the rug from them, but at this size it meets the hole's lower side in 4 directions
    # and its upper side in 10, whose extents across the line joining them share 0.44: no band
    # that lines up (`crossing`). The rug, seen on one side, is left out as clutter, and the hole
    # is filled with wood where the truth shows its black and white stripes, too bright and too
    # smooth. At 512x256 and 128 samples the band is continued (detail 0.68, total 0.238).
    ("hotel_rug_box", "total"): "measured 0.697",
    ("hotel_rug_box", "mean_error"): "measured 0.414",
    ("hotel_rug_box", "detail"): "measured 0.364",
    # The sunlit patch printed on the floor is continued under the box by the material's fill
    # (within all the bounds at 512x256 and 128 samples: mean error 0.019, total 0.140); at this
    # size the hole is a few dozen cells and the fill a little too dark.
    ("apartment_sun_box", "total"): "measured 0.234",
    ("apartment_sun_box", "mean_error"): "measured 0.066",
}


@pytest.fixture(scope="module")
def scores(tmp_path_factory: pytest.TempPathFactory) -> Callable[[str], dict[str, float]]:
    """scores(name): the figures of a scene, removed once per module run."""
    measured: dict[str, dict[str, float]] = {}

    def of(name: str) -> dict[str, float]:
        if name not in measured:
            spec = S.get(name).with_render(**SIZE)
            inp, edit, truth, mask, _, _ = _remove(spec, tmp_path_factory.mktemp(name))
            measured[name] = M.clean_removal_scores(inp, edit, truth, mask)
            print(f"{name}: {measured[name]}")
        return measured[name]

    return of


def _case(name: str, figure: str) -> pytest.param:
    reason = FAILING.get((name, figure))
    marks = [pytest.mark.xfail(strict=True, reason=reason)] if reason else []
    return pytest.param(name, figure, marks=marks, id=f"{name}-{figure}")


@pytest.mark.slow
@pytest.mark.parametrize(("name", "figure"), [_case(n, f) for n in SCENES for f in BOUNDS])
def test_photo_textured_removal_within_bounds(name: str, figure: str, scores) -> None:
    assert M.within_bounds(scores(name), (figure,)), \
        f"{name}: {figure} {scores(name)[figure]:.3f} outside {M.bounds_text((figure,))}"
