"""The fill meets the photograph without a step, keeping its own texture."""
from __future__ import annotations

import numpy as np

from addon.removal.seam import seamless_change

_H, _W = 80, 120


def _scene(step: float, seed: int = 0, *, ramp: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A textured floor relit by +5 %, a square filled with texture `step` brighter than it
    should be, and from `ramp` darker at its left edge to `ramp` brighter at its right; the
    surface is 0 below row 40, 1 above (a wall 3 times brighter)."""
    rng = np.random.default_rng(seed)
    surface = np.where(np.arange(_H)[:, None] >= 40, 0, 1) * np.ones((_H, _W), np.int64)
    base = np.where(surface == 0, 0.3, 0.9)[..., None] * np.array([1.0, 0.9, 0.8])
    radiance = base * (1 + 0.1 * rng.standard_normal((_H, _W, 1)))
    filled = np.zeros((_H, _W), bool)
    filled[25:60, 40:80] = True
    truth = radiance * 1.05
    across = np.clip((np.arange(_W) - 59.5) / 20, -1, 1)[None, :, None]
    fill = base * (1 + step + ramp * across) * 1.05 * (1 + 0.1 * rng.standard_normal((_H, _W, 1)))
    edited = np.where(filled[..., None], fill, truth)
    return radiance, (edited - radiance).astype(np.float32), filled, surface


def _step(edited: np.ndarray, filled: np.ndarray, surface: np.ndarray, s: int, *,
          edges: tuple[str, ...] = ("left", "right")) -> float:
    """Relative step of the mean over 3 pixels inside against 3 outside, on the filled rows of
    surface `s`, at the fill's `edges` together."""
    rows = np.flatnonzero((surface[:, 0] == s) & filled[:, 60])
    band = edited[rows]
    columns = {"left": (slice(40, 43), slice(37, 40)), "right": (slice(77, 80), slice(80, 83))}
    inside = sum(band[:, columns[e][0]].mean() for e in edges)
    outside = sum(band[:, columns[e][1]].mean() for e in edges)
    return abs(inside / outside - 1)


def test_a_step_on_two_surfaces_is_taken_out_and_the_texture_kept() -> None:
    radiance, change, filled, surface = _scene(0.12)
    got = seamless_change(radiance, change, filled, surface)
    before, after = radiance + change, radiance + got
    for s in (0, 1):
        assert _step(before, filled, surface, s) > 0.08
        assert _step(after, filled, surface, s) < 0.02
    assert np.array_equal(got[~filled], change[~filled])
    # the fill's own texture: its high-pass is what it was
    def high(a: np.ndarray) -> np.ndarray:
        return a[30:55, 45:75] - a[29:54, 45:75]
    assert np.abs(high(after) - high(before)).mean() < 0.05 * np.abs(high(before)).mean()


def test_without_a_step_little_changes() -> None:
    radiance, change, filled, surface = _scene(0.0, seed=1)
    got = seamless_change(radiance, change, filled, surface)
    edited = radiance + change
    assert np.abs(got - change)[filled].mean() < 0.03 * np.abs(edited[filled]).mean()


def test_no_radiance_goes_negative() -> None:
    radiance, change, filled, surface = _scene(-0.9, seed=2)
    change[filled] -= 1.0
    got = seamless_change(radiance, change, filled, surface)
    assert (radiance + got >= -1e-6).all()


def test_a_step_that_changes_along_the_border_is_followed_where_the_fill_was_synthesised() -> None:
    # too dark by 25 % at the left edge, too bright by as much at the right: averaged along the
    # whole border the two would cancel and nothing be taken out
    radiance, change, filled, surface = _scene(0.0, seed=3, ramp=0.25)
    before = radiance + change
    synthesised = radiance + seamless_change(radiance, change, filled, surface)
    continued = radiance + seamless_change(radiance, change, filled, surface, continued=filled)
    for edge in ("left", "right"):
        step = _step(before, filled, surface, 0, edges=(edge,))
        assert step > 0.2
        assert _step(synthesised, filled, surface, 0, edges=(edge,)) < 0.35 * step
        # a fill continuing the photograph's structure averages its step over twice as much of the
        # border, where a tiling's bands differ by the same step all along a straight edge
        assert _step(continued, filled, surface, 0, edges=(edge,)) > _step(synthesised, filled, surface, 0,
                                                                           edges=(edge,))


def _streaked(step: float, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """A floor of one surface with streaks along its columns (a gloss's reflections, 30 % from one
    column to the next few), a fill of streaks of its own `step` brighter than the floor."""
    rng = np.random.default_rng(seed)
    height, width = 120, 200

    def streaks() -> np.ndarray:
        f = rng.standard_normal((1, width, 1))
        f = (f + np.roll(f, 1, axis=1) + np.roll(f, -1, axis=1)) / 3
        return 1 + 0.3 * f / f.std()

    base = 0.3 * np.array([1.0, 0.9, 0.8])
    radiance = base * streaks() * (1 + 0.05 * rng.standard_normal((height, width, 1)))
    filled = np.zeros((height, width), bool)
    filled[30:90, 40:160] = True
    fill = base * (1 + step) * streaks() * (1 + 0.05 * rng.standard_normal((height, width, 1)))
    edited = np.where(filled[..., None], fill, radiance)
    return radiance, (edited - radiance).astype(np.float32), filled, np.zeros((height, width), np.int64)


def test_a_fill_brighter_all_round_than_a_texture_that_repeats_nowhere_is_brought_down() -> None:
    # 15 % brighter on every side, within the streaks' own steps: no boundary pixel's step stands
    # out, their mean over the whole border does; a darker fill is left to the local steps
    excess = {"plain": [], "unrepeated": []}
    for seed in range(4):
        radiance, change, filled, surface = _streaked(0.15, seed)
        for name, mask in (("plain", None), ("unrepeated", filled)):
            got = radiance + seamless_change(radiance, change, filled, surface, unrepeated=mask)
            excess[name].append(got[filled].mean() / radiance[filled].mean() - 1)
        radiance, change, filled, surface = _streaked(-0.15, seed)
        assert np.array_equal(seamless_change(radiance, change, filled, surface, unrepeated=filled),
                              seamless_change(radiance, change, filled, surface))
    assert np.mean(excess["plain"]) > 0.12 and np.mean(excess["unrepeated"]) < 0.5 * np.mean(excess["plain"])
