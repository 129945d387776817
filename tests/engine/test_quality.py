"""Quality presets and parameter overrides."""
from __future__ import annotations

import dataclasses

import pytest

from addon.errors import DimredError
from addon.quality import PRESETS, params_for, rough


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
