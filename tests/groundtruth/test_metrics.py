"""The ground-truth scores on small hand-made panoramas (numpy only, no rendering)."""
from __future__ import annotations

import numpy as np
import pytest

from scenes import metrics as M

H, W = 24, 32


def _scene(seed: int = 0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(input, truth, mask, shadow): a noisy room, an object, and its shadow 40 % dark."""
    rng = np.random.default_rng(seed)
    truth = (0.5 + 0.05 * rng.standard_normal((H, W, 3))).clip(0.1)
    mask = np.zeros((H, W), bool)
    mask[8:10, 10:13] = True
    shadow = np.zeros((H, W), bool)
    shadow[10:17, 4:22] = True
    inp = truth.copy()
    inp[shadow] *= 0.6
    inp[mask] = (0.9, 0.1, 0.1)
    return inp, truth, mask, shadow


def test_luminance_weights() -> None:
    rgb = np.array([[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 1.0]]])
    np.testing.assert_allclose(M.luminance(rgb), [[0.2126, 0.7152, 0.0722, 1.0]])


def test_blur_wraps_at_seam_and_clamps_at_poles() -> None:
    a = np.zeros((4, 6))
    a[2, 0] = 9.0
    b = M.box_blur3(a)
    # The spike in column 0 spreads to the last column across the seam.
    assert b[2, 5] == pytest.approx(1.0) and b[2, 1] == pytest.approx(1.0)
    assert b[2, 2] == 0.0
    # At the pole the edge row is repeated rather than wrapped to the other pole.
    top = np.zeros((4, 6))
    top[0, 3] = 9.0
    bt = M.box_blur3(top)
    assert bt[0, 3] == pytest.approx(2.0) and bt[3, 3] == 0.0
    # Means are preserved along u, constants stay constant, colour axes are kept.
    np.testing.assert_allclose(M.box_blur3(np.full((5, 7, 3), 0.3)), 0.3)


def test_dilate_wraps_at_seam_and_clamps_at_poles() -> None:
    m = np.zeros((5, 8), bool)
    m[0, 7] = True
    d = M.dilate(m, 2)
    assert d[0, 0] and d[0, 1] and not d[0, 2]
    assert d[2, 5] and not d[3, 7]
    assert d.sum() == 3 * 5


def test_ratio_is_one_for_input_and_zero_for_truth() -> None:
    inp, truth, mask, _ = _scene()
    assert M.lighting_error_ratio(inp, inp, truth, mask) == pytest.approx(1.0)
    assert M.lighting_error_ratio(inp, truth, truth, mask) == pytest.approx(0.0)
    half = 0.5 * (inp + truth)
    assert M.lighting_error_ratio(inp, half, truth, mask) == pytest.approx(0.5)


def test_region_is_the_shadow_outside_the_mask() -> None:
    inp, truth, mask, shadow = _scene()
    region = M.lighting_region(inp, truth, mask)
    assert not (region & M.dilate(mask, 2)).any()
    # The blurred shadow edge reaches one pixel further; nothing else is flagged.
    assert region[shadow & ~M.dilate(mask, 2)].mean() > 0.9
    assert not (region & ~M.dilate(shadow, 1)).any()


def test_region_ignores_noise_where_paths_differ() -> None:
    inp, truth, mask, shadow = _scene()
    rng = np.random.default_rng(1)
    noisy = inp * (1.0 + 0.3 * rng.standard_normal((H, W, 1)) * (~shadow)[..., None]).clip(0.2)
    region = M.lighting_region(noisy, truth, mask)
    # 30 % pixel noise everywhere but in the shadow: a 2 % test alone would flag most pixels,
    # the 3-sigma test a few by chance.
    assert (region & ~M.dilate(shadow, 1)).mean() < 0.01
    # Near the noise and the shadow's own edge the noise estimate rises; inside it does not.
    interior = ~M.dilate(~shadow, 2) & ~M.dilate(mask, 2)
    assert interior.sum() > 20 and region[interior].all()


def test_region_does_not_depend_on_exposure() -> None:
    inp, truth, mask, _ = _scene()
    assert np.array_equal(M.lighting_region(inp, truth, mask),
                          M.lighting_region(100.0 * inp, 100.0 * truth, mask))


def test_empty_region_raises() -> None:
    _, truth, mask, _ = _scene()
    with pytest.raises(ValueError):
        M.lighting_error_ratio(truth, truth, truth, mask)


def test_far_damage() -> None:
    inp, truth, mask, shadow = _scene()
    assert M.far_damage(inp, inp, truth, mask) == 0.0
    assert M.far_damage(inp, truth, truth, mask) <= 0.0
    # Brightening a far corner by 10 % is damage of 10 % of the truth there.
    bad = inp.copy()
    bad[:4, 20:30] *= 1.1
    assert M.far_damage(inp, bad, truth, mask, percentile=100.0) == pytest.approx(0.1, rel=0.02)
    # The same change inside the shadow is not "far".
    ok = inp.copy()
    ok[shadow] *= 1.1
    assert M.far_damage(inp, ok, truth, mask, percentile=100.0) <= 0.0


def test_bleeding_error() -> None:
    inp, truth, mask, shadow = _scene()
    reddish = inp.copy()
    reddish[shadow] *= (1.3, 0.9, 0.9)
    e_in, e_truth = M.bleeding_error(reddish, truth, truth, mask)
    assert e_truth == 0.0 and e_in > 0.05
    e_in2, e_same = M.bleeding_error(reddish, reddish, truth, mask)
    assert e_same == e_in2 == e_in


def test_chromaticity_of_black_is_grey() -> None:
    c = M.chromaticity(np.zeros((3, 4, 3)))
    np.testing.assert_allclose(c, 1.0 / 3.0)


def test_noise_floor() -> None:
    inp, truth, mask, shadow = _scene()
    # Without independent noise only the blurred ratio's edges are left: a small floor.
    assert 0.0 <= M.noise_floor(inp, truth, mask) < 0.2
    rng = np.random.default_rng(2)
    noisy = truth * (1.0 + 0.2 * rng.standard_normal((H, W, 1))).clip(0.2)
    noisy_in = noisy.copy()
    noisy_in[shadow] *= 0.6
    noisy_in[mask] = inp[mask]
    assert M.noise_floor(noisy_in, truth, mask) > M.noise_floor(inp, truth, mask)


def test_summary_keys() -> None:
    inp, truth, mask, _ = _scene()
    s = M.summary(inp, truth, truth, mask)
    assert s["lighting_error_ratio"] == 0.0 and s["region_pixels"] > 0
    assert set(s) == {"region_pixels", "lighting_error_ratio", "noise_floor", "far_damage",
                      "bleeding_input", "bleeding_edit"}


def test_relocation_region_and_ratio() -> None:
    """The region holds both placements with their shadows; moving nothing scores 1, the truth 0."""
    inp, empty, mask, shadow = _scene()
    moved = empty.copy()
    new_mask = np.roll(mask, 12, axis=1)
    new_shadow = np.roll(shadow, 12, axis=1) & ~shadow
    moved[new_shadow] *= 0.6
    moved[new_mask] = (0.9, 0.1, 0.1)
    region = M.relocation_region(inp, moved, empty, mask, new_mask)
    assert region[mask].all() and region[new_mask].all()
    assert region[shadow & ~M.dilate(mask | new_mask, 2)].mean() > 0.9
    assert region[new_shadow & ~M.dilate(mask | new_mask, 2)].mean() > 0.9
    assert not (region & ~M.dilate(shadow | new_shadow | mask | new_mask, 2)).any()
    assert M.relocation_error_ratio(inp, inp, moved, region) == pytest.approx(1.0)
    assert M.relocation_error_ratio(inp, moved, moved, region) == pytest.approx(0.0)
    with pytest.raises(ValueError):
        M.relocation_error_ratio(inp, inp, moved, np.zeros_like(region))


def test_ghost_share_counts_the_object_pixels_left_visibly_wrong() -> None:
    rng = np.random.default_rng(3)
    truth = (0.5 + 0.05 * rng.standard_normal((H, W, 3))).clip(0.1)
    mask = np.zeros((H, W), bool)
    mask[8:14, 10:18] = True
    # A proxy 4 px off: the left half of the object is still there, dark, in the edit.
    edit = truth.copy()
    edit[8:14, 10:14] = 0.1
    assert M.ghost_share(truth, truth, mask) == 0.0
    # The blur spreads the ghost by a pixel, a third of its contrast: under the 30 % threshold.
    assert M.ghost_share(edit, truth, mask) == pytest.approx(0.5)
    assert M.ghost_share(100.0 * edit, 100.0 * truth, mask) == pytest.approx(0.5)
    assert M.ghost_share(edit, truth, mask, threshold=0.9) == 0.0
    with pytest.raises(ValueError):
        M.ghost_share(edit, truth, np.zeros_like(mask))


def test_relit_detail_ratio_sees_a_shadow_relit_with_its_noise() -> None:
    inp, truth, mask, shadow = _scene(3)
    rng = np.random.default_rng(4)
    noisy = inp.copy()
    noisy[shadow] += 0.05 * rng.standard_normal((int(shadow.sum()), 3))  # the dark pixels' own noise
    relit_noise = noisy.copy()
    relit_noise[shadow] /= 0.6  # relit, noise and all
    ratio, pixels = M.relit_detail_ratio(noisy, relit_noise, truth, mask)
    assert ratio > 1.5 and 0 < pixels <= shadow.sum()
    assert M.relit_detail_ratio(noisy, truth, truth, mask)[0] == pytest.approx(1.0)
    with pytest.raises(ValueError, match="brighter"):
        M.relit_detail_ratio(truth, truth, truth, mask)


def test_bruise_share_counts_fill_pixels_darker_than_the_clean_surface() -> None:
    rng = np.random.default_rng(3)
    truth = (0.5 + 0.02 * rng.standard_normal((H, W, 3))).clip(0.1)
    mask = np.zeros((H, W), bool)
    mask[8:16, 8:20] = True  # 96 pixels
    assert M.bruise_share(truth, truth, mask) == 0.0
    # A 2 x 12 dark stripe copied into the fill: its 24 pixels, and the 3x3 blur's row either side
    # of it, where a third of the window is dark (0.35 < 0.8 x 0.47), less their ends (two ninths).
    edit = truth.copy()
    edit[11:13, 8:20] = 0.05
    assert M.bruise_share(edit, truth, mask) == pytest.approx((24 + 2 * 10) / 96)
    # 15 % darker everywhere is a mismatch of brightness, not a bruise.
    assert M.bruise_share(truth * 0.85, truth, mask) == 0.0
    # The same stripe is no bruise where the clean surface under the object shows a stripe as
    # dark, or, when asked to look that far, one nearby.
    striped = truth.copy()
    striped[14:16, 8:20] = 0.05
    assert M.bruise_share(edit, striped, mask) == 0.0
    nearby = truth.copy()
    nearby[4:6, 2:30] = 0.05
    assert M.bruise_share(edit, nearby, mask) > 0.4
    assert M.bruise_share(edit, nearby, mask, width_px=4) == 0.0
    with pytest.raises(ValueError, match="empty"):
        M.bruise_share(truth, truth, np.zeros((H, W), bool))


def test_neighbour_patch_takes_the_shift_that_matches_the_hidden_surface() -> None:
    inp, truth, mask, _ = _scene()
    # Rows differ and columns do not: a patch beside the object is the hidden one exactly, a
    # patch above or below it is not.
    striped = np.broadcast_to(truth[:, :1], truth.shape).copy()
    inp = np.where(mask[..., None], inp, striped)
    got = M.neighbour_patch_scores(inp, striped, mask)
    assert got["shift"][0] == 0 and abs(got["shift"][1]) == 3 + 2
    assert got["total"] == pytest.approx(0.0, abs=1e-12) and got["mean_error"] == pytest.approx(0.0, abs=1e-12)


def test_neighbour_patch_of_a_noisy_surface_keeps_its_detail_and_misses_its_pixels() -> None:
    inp, truth, mask, _ = _scene(seed=3)
    got = M.neighbour_patch_scores(inp, truth, mask)
    assert got["light"] == pytest.approx(0.0, abs=1e-12)  # the light is the truth's
    assert 0.5 < got["detail"] < 2.0 and got["total"] > 0.0


def test_neighbour_patch_needs_room_beside_the_object() -> None:
    inp, truth, _, _ = _scene()
    band = np.zeros((H, W), bool)
    band[2:H - 2, :] = True  # all the way round and nearly pole to pole
    with pytest.raises(ValueError, match="no neighbouring patch"):
        M.neighbour_patch_scores(inp, truth, band)


def test_the_bounds_in_words_and_a_draw_within_them() -> None:
    assert M.bounds_text(("mean_error", "detail")) == "mean error <= 0.05, detail 0.8-1.2"
    figures = ("mean_error", "detail", "total")
    assert M.within_bounds({"mean_error": 0.05, "detail": 0.8, "total": 0.2}, figures)
    assert not M.within_bounds({"mean_error": 0.01, "detail": 1.21, "total": 0.1}, figures)
    assert not M.within_bounds({"mean_error": 0.01, "detail": 1.0, "total": 0.1, "bruise_share": 0.03,
                                "far_damage": 0.0})
