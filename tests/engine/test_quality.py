"""Quality presets and parameter overrides."""
from __future__ import annotations

import dataclasses

import pytest

from addon.errors import DimredError
from addon.quality import MIN_WORKING_WIDTH, PRESETS, params_for, rough


def test_presets_and_overrides():
    assert params_for("balanced") == PRESETS["balanced"]
    assert params_for("final", patches=77).patches == 77
    with pytest.raises(DimredError, match="unknown quality 'best'"):
        params_for("best")
    with pytest.raises(DimredError, match="unknown parameter"):
        params_for("draft", patchez=3)


def test_rough_takes_the_drafts_solver_and_keeps_the_rest():
    final = params_for("final", seed=7, synth_neighbourhood=9)
    got = rough(final)
    draft = PRESETS["draft"]
    assert (got.patches, got.max_senders, got.max_bounces, got.fine_pixels) == (
        draft.patches, draft.max_senders, draft.max_bounces, draft.fine_pixels)
    kept = {"seed", "synth_neighbourhood", "synth_levels", "synth_generations", "raster_cell", "exemplar_margin",
            "insertion_passes"}
    assert {f.name: getattr(got, f.name) for f in dataclasses.fields(got) if f.name in kept} == {
        name: getattr(final, name) for name in kept}
    assert got.insertion_passes == 3


@pytest.mark.parametrize("width", [127, 126, 1023, 0, -512, 512.0, True, "1024"])
def test_a_working_width_that_is_not_an_even_count_of_at_least_the_minimum_is_refused(width):
    expected = f"working_width must be an even number of pixels, at least {MIN_WORKING_WIDTH}"
    with pytest.raises(DimredError, match=expected):
        params_for("balanced", working_width=width)


def test_a_working_width_override_replaces_the_presets():
    assert MIN_WORKING_WIDTH == 128
    assert params_for("final", working_width=MIN_WORKING_WIDTH).working_width == MIN_WORKING_WIDTH
    assert params_for("draft", working_width=4096).working_width == 4096
