"""The planks' profile across them, folded over their width: against point-sampled seams."""
import numpy as np
import pytest

from addon.synthesis.plank_profile import fold_profile

WIDTH, SEAM, OFFSET = 0.163, 0.004, 0.037


def _floor(*, turn=0.0, noise=0.1, n=60_000, seed=1, width=WIDTH):
    """Pixels scattered over 3 x 3 m of floor, positions across and along the proxy's axes; the
    planks turned `turn` degrees against them. Each pixel's detail is 1 plus noise, 0.4 where its
    centre falls on a 4 mm seam (a point-sampled render); and which pixels do."""
    rng = np.random.default_rng(seed)
    across, along = rng.uniform(-1.5, 1.5, n), rng.uniform(-1.5, 1.5, n)
    t = np.radians(turn)
    seam = np.mod(across * np.cos(t) - along * np.sin(t) - OFFSET, width) < SEAM
    return across, along, 1.0 + noise * rng.standard_normal(n) - 0.6 * seam, seam


@pytest.mark.parametrize("turn", [0.0, 1.0, 3.0, -5.0])
def test_the_profile_puts_the_seams_where_the_pixels_fall_on_them(turn):
    across, along, detail, seam = _floor(turn=turn)
    got = fold_profile(across, along, detail)
    assert got is not None
    assert got.width == pytest.approx(WIDTH / np.cos(np.radians(turn)), abs=2e-4)
    assert got.shear == pytest.approx(np.tan(np.radians(turn)), abs=1e-3)
    # pixels not seen, on the same floor: the profile tells which of them fall on a seam
    across, along, _, seam = _floor(turn=turn, seed=2)
    factor = got.at(across, along)
    assert factor[seam].mean() < 0.55 and factor[~seam].mean() > 0.98
    # a factor, not an offset: it averages 1 over the pixels, the fill's mean stays
    assert got.at(across, along).mean() == pytest.approx(1.0, abs=0.01)


def test_half_the_width_folds_the_seams_too_but_is_not_taken():
    """Folded over half a width every seam lands in one bin as well, but so does every plank's
    middle; over a third, a quarter, likewise. Wide planks put all of these in the range."""
    across, along, detail, _ = _floor(width=0.4)
    got = fold_profile(across, along, detail)
    assert got.width == pytest.approx(0.4, abs=5e-4)


def test_a_floor_without_planks_or_with_too_few_pixels_has_no_profile():
    rng = np.random.default_rng(0)
    across, along = rng.uniform(-1.5, 1.5, (2, 60_000))
    assert fold_profile(across, along, 1.0 + 0.1 * rng.standard_normal(60_000)) is None
    across, along, detail, _ = _floor(n=200)
    assert fold_profile(across, along, detail) is None


def test_the_same_pixels_give_the_same_profile_and_noise_blurs_it_without_moving_it():
    across, along, detail, _ = _floor()
    clean, again = fold_profile(across, along, detail), fold_profile(across, along, detail)
    np.testing.assert_array_equal(clean.factors, again.factors)
    # render noise 7 times the clean floor's, as a few samples per pixel give in a dark corner
    across, along, detail, seam = _floor(noise=0.7)
    noisy = fold_profile(across, along, detail)
    assert noisy is not None and noisy.significance < clean.significance / 10
    assert fold_profile(*_floor(noise=2.0)[:3]) is None  # nothing above the noise: no profile
    assert noisy.width == pytest.approx(WIDTH, abs=3e-4)
    assert np.mean(noisy.at(across, along)[seam]) < 0.6 < 0.95 < np.mean(noisy.at(across, along)[~seam])
