"""The relit pixels' noise matched to their surface's, on photographs built from arrays: a
textured floor with a shadow the removal lights up again, its noise either growing in the dark
(a single exposure, a renderer's few samples) or not (a bracketed merge)."""
from __future__ import annotations

import numpy as np
import pytest

from addon.light.radiosity import LUMA
from addon.removal.relit_noise import quiet_relit, relit_noise_stage
from addon.report import Report

H, W = 160, 200
GAIN = 3.0  # the shadow keeps a third of the light
TEXTURE = 0.15  # the reflectance's relative detail


def _robust_sd(values: np.ndarray) -> float:
    return float(1.4826 * np.median(np.abs(values - np.median(values))))


def _relative_detail(image: np.ndarray, where: np.ndarray) -> float:
    """The robust spread of the luminance against its 3 x 3 mean, relative to that mean."""
    y = image @ LUMA
    padded = np.pad(y, 1, mode="edge")
    mean = sum(padded[1 + dr:1 + dr + H, 1 + dc:1 + dc + W] for dr in (-1, 0, 1) for dc in (-1, 0, 1)) / 9
    return _robust_sd(((y - mean) / mean)[where])


def _shadow(*, edge: float = 6.0) -> np.ndarray:
    """(H, W) the share of the light each pixel keeps with the object: 1 / GAIN in a disc,
    rising to 1 over `edge` pixels."""
    r = np.hypot(*np.meshgrid(np.arange(H) - H / 2, np.arange(W) - W / 2, indexing="ij"))
    return 1.0 / GAIN + (1.0 - 1.0 / GAIN) * np.clip((r - 30.0) / edge, 0.0, 1.0)


def _scene(seed: int, *, read_noise: float, relative_noise: float = 0.02, edge: float = 6.0):
    """The photograph (H, W, 3), the removal's change (relighting every pixel back to full
    light), the room without the object and the shadowed pixels."""
    rng = np.random.default_rng(seed)
    rho = 0.5 * (1.0 + TEXTURE * rng.standard_normal((H, W)))[..., None] * np.array([1.0, 0.9, 0.7])
    kept = _shadow(edge=edge)

    def photograph(light: np.ndarray) -> np.ndarray:
        clean = rho * light[..., None]
        shot = clean * relative_noise * rng.standard_normal(clean.shape)
        noise = shot + read_noise * rng.standard_normal(clean.shape)
        return np.maximum(clean + noise, 1e-4).astype(np.float32)

    shot = photograph(kept)
    change = shot * (1.0 / kept[..., None] - 1.0)
    return shot, change.astype(np.float32), photograph(np.ones((H, W))), kept < 0.4


def test_a_relit_shadow_keeps_the_noise_of_the_lit_surface_around_it():
    photo, change, truth, shadow = _scene(0, read_noise=0.04)
    quiet = quiet_relit(photo, change, np.zeros((H, W), dtype=np.int64))
    lit = _relative_detail(truth, shadow)
    assert _relative_detail(photo + change, shadow) > 1.5 * lit  # the speckle the stage is for
    assert 0.8 * lit < _relative_detail(photo + quiet.change, shadow) < 1.2 * lit
    # The light itself is relit as before.
    relit, quieted = (photo + change) @ LUMA, (photo + quiet.change) @ LUMA
    assert quieted[shadow].mean() == pytest.approx(relit[shadow].mean(), rel=0.01)
    assert quiet.growth.keys() == {0} and quiet.growth[0] > 0.3
    assert quiet.pixels >= shadow.sum()
    assert (photo + quiet.change >= 0).all()


def test_a_photograph_as_clean_in_its_shadows_as_in_its_lights_is_left_nearly_as_it_is():
    photo, change, _, shadow = _scene(1, read_noise=0.0, relative_noise=0.05)
    quiet = quiet_relit(photo, change, np.zeros((H, W), dtype=np.int64))
    assert quiet.growth.get(0, 0.0) < 0.3
    moved = np.abs((quiet.change - change) @ LUMA)[shadow].mean()
    assert moved < 0.03 * ((photo + change) @ LUMA)[shadow].mean()


def test_a_sharp_shadow_edge_keeps_its_light_on_both_sides():
    # Against the photograph's own neighbours a pixel just inside a sharp shadow is far darker
    # than its mean: that is the shadow, not noise, and must not be lifted or dimmed.
    photo, change, _, shadow = _scene(2, read_noise=0.04, edge=0.5)
    quiet = quiet_relit(photo, change, np.zeros((H, W), dtype=np.int64))
    edge = shadow & ~np.roll(shadow, 1, 0) | shadow & ~np.roll(shadow, -1, 0)
    relit, quieted = (photo + change) @ LUMA, (photo + quiet.change) @ LUMA
    assert quieted[edge].mean() == pytest.approx(relit[edge].mean(), rel=0.02)


def test_pixels_not_relit_and_other_surfaces_are_left_alone():
    photo, change, _, shadow = _scene(3, read_noise=0.04)
    surface = np.zeros((H, W), dtype=np.int64)
    surface[:, : W // 2] = -1  # the object, a light, a pixel too dark: no relighting to quiet
    surface[:, W // 2: W // 2 + 10] = 1  # another surface, ten times brighter, beside the shadow
    photo[:, W // 2: W // 2 + 10] *= 10.0
    change[~shadow] = 0.0
    quiet = quiet_relit(photo, change, surface)
    assert np.array_equal(quiet.change[:, : W // 2], change[:, : W // 2])
    assert np.array_equal(quiet.change[~shadow], change[~shadow])
    # The relit pixels beside the bright surface are as bright as the others of their surface.
    quieted = (photo + quiet.change) @ LUMA
    beside = shadow & (np.arange(W) == W // 2 + 10)[None, :]
    inner = shadow & (np.arange(W) > W // 2 + 14)[None, :]
    assert beside.sum() > 10
    assert quieted[beside].mean() == pytest.approx(quieted[inner].mean(), rel=0.05)
    assert set(quiet.growth) == {0, 1}  # measured on each surface apart


def test_too_few_relit_pixels_to_measure_change_nothing():
    photo, change, _, _ = _scene(4, read_noise=0.04)
    small = np.zeros_like(change)
    small[78:83, 98:103] = 2.0 * photo[78:83, 98:103]  # 25 pixels relit three times over
    change = small
    quiet = quiet_relit(photo, change, np.zeros((H, W), dtype=np.int64))
    assert quiet.growth == {} and quiet.pixels == 0
    assert np.array_equal(quiet.change, change)


def test_the_stage_reports_what_it_did_and_can_be_turned_off():
    photo, change, _, _ = _scene(5, read_noise=0.04)
    surface = np.zeros((H, W), dtype=np.int64)
    rep = Report()
    on = relit_noise_stage(photo, change, surface, enabled=True, rep=rep)
    done = rep.as_dict()
    assert "relit_noise" in done["seconds"] and done["relit_noise"]["pixels"] == on.pixels > 0
    assert set(done["relit_noise"]["growth"]) == {"0"}
    rep = Report()
    off = relit_noise_stage(photo, change, surface, enabled=False, rep=rep)
    assert off.change is change and off.pixels == 0
    assert [s["stage"] for s in rep.as_dict()["skipped"]] == ["relit_noise"]


def test_a_shadow_on_a_surface_seen_nowhere_else_changes_nothing():
    # Every pixel of the surface brightened: no unchanged pixel tells its own detail.
    photo, change, _, _ = _scene(6, read_noise=0.04)
    change = photo * 2.0
    quiet = quiet_relit(photo, change, np.zeros((H, W), dtype=np.int64))
    assert quiet.growth == {} and np.array_equal(quiet.change, change)
