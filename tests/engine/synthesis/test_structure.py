"""Structure-aware fill: the translations of tiled and planked textures, the shift map that
composes a hole from shifted copies, and the blend; against hand-made periodic arrays."""
import numpy as np
import pytest

from addon.segmentation.masks import dilate
from addon.synthesis import structure
from addon.synthesis.material import ring_widths
from addon.synthesis.shift_map import candidate_shifts, lattice_shifts, shift_map
from addon.synthesis.structure import fill_structured, structure_fill
from addon.synthesis.texture import SynthesisParams
from addon.synthesis.translations import DOMINANT, dominant_translations


def _tiles(size=160, period=20, grout=2, seed=0):
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size]
    img = np.full((size, size, 3), 0.7) + 0.02 * rng.standard_normal((size, size, 1))
    img[((y % period) < grout) | ((x % period) < grout)] = 0.25
    return img.astype(np.float32)


def _planks(size=160, width=12, length=72, seed=0):
    """Planks along x of random shades, joints staggered by half a plank every other row."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size]
    row = y // width
    piece = (x + (row % 2) * length // 2) // length
    shade = 0.4 + 0.3 * rng.random((size // width + 1, size // length + 2))
    img = shade[row, piece][..., None] * np.array([1.0, 0.7, 0.45]) + 0.01 * rng.standard_normal((size, size, 1))
    joint = ((y % width) == 0) | (((x + (row % 2) * length // 2) % length) == 0)
    img[joint] *= 0.4
    return img.astype(np.float32)


def _grain_planks(size=160, seed=0):
    """`_planks` with a wood grain of a random phase in every row that repeats every 8 cells along
    the planks (stool's and warm_cylinder's at 1024x512 every 7): the texture then matches itself
    best a few cells along the planks, not at a plank's length."""
    y, x = np.mgrid[:size, :size]
    phase = 2 * np.pi * np.random.default_rng(seed + 1).random(size)[y]
    return (_planks(size, seed=seed) * (1.0 + 0.15 * np.sin(2 * np.pi * x / 8 + phase))[..., None]).astype(np.float32)


def _noise(size=160, seed=0):
    rng = np.random.default_rng(seed)
    white = rng.standard_normal((size + 4, size + 4, 1))
    smooth = sum(white[dy:dy + size, dx:dx + size] for dy in range(5) for dx in range(5)) / 5
    return (0.5 + 0.08 * smooth * np.array([1.0, 0.9, 0.8])).astype(np.float32)


def _hole(size, lo, hi):
    m = np.zeros((size, size), bool)
    m[lo:hi, lo + 5:hi + 9] = True
    return m


def _band_pass_correlation(out, truth, hole):
    def bp(a):
        y = a.mean(axis=2)
        k = np.ones(3) / 3
        s = np.apply_along_axis(lambda r: np.convolve(r, k, "same"), 0, y)
        s = np.apply_along_axis(lambda r: np.convolve(r, k, "same"), 1, s)
        return (y - s)[hole]
    a, b = bp(out), bp(truth)
    a, b = a - a.mean(), b - b.mean()
    return float((a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum()))


def test_translations_of_tiles_are_their_period():
    img = _tiles()
    hole = _hole(160, 60, 100)
    tr = dominant_translations(img, ~hole, hole)
    assert tr.dominant
    assert tr.contrast[0] < 0.3
    # every shift found is a whole number of periods in both axes
    assert np.all(tr.shifts % 20 == 0), tr.shifts


def test_stochastic_texture_has_no_dominant_translation_and_no_structure_fill():
    img = _noise()
    hole = _hole(160, 60, 100)
    assert not dominant_translations(img, ~hole, hole).dominant
    assert structure_fill(img, ~hole, hole) is None


# planks of random shades: the hidden planks' shades are not in the picture, their mean neither
@pytest.mark.parametrize("texture, least, mean_off", [(_tiles, 0.9, 0.03), (_planks, 0.6, 0.1)])
def test_structure_fill_continues_lines_in_phase(texture, least, mean_off):
    truth = texture()
    hole = _hole(160, 55, 105)
    seen = np.where(hole[..., None], 0, truth)
    got = structure_fill(seen, ~hole, hole)
    assert got is not None and got.covered[hole].all()
    out = got.image
    assert np.all(out[~hole] == seen[~hole])
    assert _band_pass_correlation(out, truth, hole) >= least
    assert abs(out[hole].mean() / truth[hole].mean() - 1) < mean_off


def test_planks_whose_grain_repeats_within_a_few_cells_are_composed():
    """Grain streaks make a short shift along the planks the best repeat. The seams run on
    through the interpolated lines, and the copies, which give the fine detail (`plane_fill`),
    keep the grain in phase, better than the per-pixel synthesis does."""
    truth = _grain_planks()
    hole = _hole(160, 55, 105)
    seen = np.where(hole[..., None], 0, truth)
    best = dominant_translations(seen, ~hole, hole).shifts[0]
    assert best[0] == 0 and 0 < abs(best[1]) < 4 * SynthesisParams().neighbourhood
    filled = fill_structured(seen, ~hole, hole, SynthesisParams())
    composed, got = filled.image, filled.structure
    per_pixel = fill_structured(seen, ~hole, hole, SynthesisParams(), structure=False).image
    assert got is not None and got.covered[hole].all()
    assert _band_pass_correlation(composed, truth, hole) >= 0.7
    assert _band_pass_correlation(got.shifts.image, truth, hole) > _band_pass_correlation(per_pixel, truth, hole) + 0.02


def test_mean_follows_surroundings_under_a_brightness_step():
    """Copies from darker tiles farther off are brought to the hole's own surroundings."""
    truth = _tiles()
    y = np.mgrid[:160, :160][0]
    lit = truth * (0.6 + 0.4 * (y < 120))[..., None]  # the far floor, where copies come from, darker
    hole = _hole(160, 50, 90)
    got = structure_fill(np.where(hole[..., None], 0, lit), ~hole, hole)
    assert abs(got.image[hole].mean() / lit[hole].mean() - 1) < 0.05


@pytest.mark.parametrize("texture, least", [(_tiles, 0.9), (_planks, 0.6)])
def test_same_seed_same_fill_other_seed_other_fill_of_the_same_quality(texture, least):
    """On planks the lines are interpolated whatever the seed; the copies, which give the fill
    its fine detail, are another seed's."""
    truth = texture(seed=3)
    hole = _hole(160, 55, 105)
    seen = np.where(hole[..., None], 0, truth)
    a, b = (structure_fill(seen, ~hole, hole, seed=1) for _ in range(2))
    c = structure_fill(seen, ~hole, hole, seed=2)
    np.testing.assert_array_equal(a.image, b.image)
    np.testing.assert_array_equal(a.shifts.image, b.shifts.image)
    assert not np.array_equal(a.shifts.image[hole], c.shifts.image[hole])
    assert min(_band_pass_correlation(a.image, truth, hole), _band_pass_correlation(c.image, truth, hole)) >= least


def test_seed_varies_the_axis_shifts_lengths_only():
    hole = _hole(160, 55, 105)
    repeats = np.array([[20, 0], [0, 20]])
    a, b, c = (candidate_shifts(repeats, hole, seed=s) for s in (1, 1, 2))
    np.testing.assert_array_equal(a, b)
    assert not np.array_equal(a, c)
    np.testing.assert_array_equal(a[:2], repeats)
    np.testing.assert_array_equal(c[:2], repeats)
    assert np.all((a[2:] == 0).sum(axis=1) == 1)  # the rest lie along an axis


def test_labels_of_a_tiling_are_its_repeats():
    img = _tiles()
    hole = _hole(160, 55, 105)
    repeats = dominant_translations(img, ~hole, hole).shifts[:8]
    shifts = lattice_shifts(repeats, img, ~hole, hole)
    assert len(shifts) >= 8
    assert np.all(shifts % 20 == 0), shifts
    # up to 1.5 times the hole's extent (54 cells), or the longest repeat found
    lengths = np.hypot(*shifts.T)
    assert lengths.min() >= 6 and lengths.max() <= max(1.5 * 54, np.hypot(*repeats.T).max())


def test_a_band_of_shadow_left_along_the_border_does_not_put_tiles_out_of_phase():
    """A proxy modelled off the object leaves part of its shadow beside the hole: a darker band
    the copies must not chase by shifting the tiles."""
    truth = _tiles(period=24, grout=3)
    hole = _hole(160, 55, 105)
    y, x = np.mgrid[:160, :160]
    band = (y >= 105) & (y < 113) & (x >= 55) & (x < 118)
    seen = np.where(hole[..., None], 0, truth * np.where(band, 0.55, 1.0)[..., None])
    got = structure_fill(seen, ~hole, hole)
    assert got is not None and got.covered[hole].all()
    assert _band_pass_correlation(got.image, truth, hole) >= 0.9


@pytest.mark.parametrize("tint, composed", [(1.0, True), (1.15, False)])
def test_copies_in_colours_the_ring_does_not_show_are_no_composition(tint, composed):
    """The exemplar's colours are told with a step's tolerance, so it may hold a region of another
    colour beyond the ring around the hole (the lit side of a bed). Where the shift map copies
    that into the hole (here drawn to it by what the repainted pixels show), the synthesis fills
    alone; the same floor in one colour is composed."""
    hole = _hole(160, 60, 100)
    colour = np.array([1.0, tint, 1.0 / tint], np.float32)
    floor = _tiles() * np.array([1.0, 0.85, 0.65], np.float32)
    beyond = ~dilate(hole, ring_widths(hole)[0] + 1)
    seen = np.where(hole[..., None], 0, np.where(beyond[..., None], floor * colour, floor))
    got = structure_fill(seen, ~hole, hole, guide=floor * colour, guided=hole)
    assert (got is not None) == composed


def test_sharp_sources_preferred_over_coarse_ones():
    """With the far half marked coarse, the copies come from the near half."""
    img = _tiles()
    hole = _hole(160, 60, 100)
    y = np.mgrid[:160, :160][0]
    footprint = np.where(y < 80, 4.0, 1.0)  # rows above the middle are resolved 4x more coarsely
    footprint[hole] = 1.0
    shifts = candidate_shifts(dominant_translations(img, ~hole, hole).shifts, hole)
    got = shift_map(img, ~hole, hole, shifts, footprint=footprint)
    ys, _ = np.nonzero(hole)
    src_rows = ys + got.shifts[got.labels[hole], 0]
    assert (src_rows >= 80).mean() > 0.9


def test_shift_map_leaves_what_no_shift_reaches():
    img = _tiles()
    hole = np.zeros((160, 160), bool)
    hole[:, 70:90] = True  # a strip: vertical shifts never leave it
    got = shift_map(img, ~hole, hole, np.array([[20, 0], [-20, 0]]))
    assert not got.covered.any()
    np.testing.assert_array_equal(got.image, img)
    got = shift_map(img, ~hole, hole, np.array([[0, 20], [0, -20]]))
    assert got.covered[hole].all()


def _striped_planks(size=160, seed=0, width=24):
    """Planks of random lengths and tones whose grain repeats every 7 rows across them (the
    benchmark's planks): a tiling whose list of translations holds shifts too long to check
    around a small hole, which are no repeats."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size]
    row = y // width
    length, start = rng.integers(50, 100, size // width + 1), rng.integers(0, 100, size // width + 1)
    tone = 1 + 0.10 * rng.standard_normal((size // width + 1, size))
    shade = tone[row, (x + start[row]) // length[row]] * (0.85 + 0.075 * (1 + np.sin(2 * np.pi * y / 7.0)))
    img = np.array([0.55, 0.36, 0.20]) * shade[..., None] + 0.01 * rng.standard_normal((size, size, 1))
    img[((y % width) < 2) | (((x + start[row]) % length[row]) < 2)] *= 0.4
    return img.astype(np.float32)


def test_a_tilings_labels_combine_its_repeats_only():
    truth = _striped_planks()
    hole = _hole(160, 64, 96)
    got = structure_fill(np.where(hole[..., None], 0, truth), ~hole, hole)
    t = got.translations
    assert t.tiling and (t.contrast[:8] > DOMINANT).any()  # the list holds shifts that are no repeat
    base = t.shifts[t.contrast <= DOMINANT][:8]
    base = np.concatenate([base, -base])
    combined = {tuple(x) for x in np.concatenate([base, 2 * base, (base[:, None] + base[None]).reshape(-1, 2)])}
    assert {tuple(x) for x in got.shifts.shifts} <= combined


@pytest.mark.parametrize("texture, along", [(_planks, 1), (_grain_planks, 1), (_tiles, None), (_noise, None)])
def test_the_planks_axis_is_found_whichever_raster_axis_they_follow(texture, along):
    img = texture()
    hole = _hole(160, 55, 105)
    assert structure._plank_axis(img, ~hole, hole) == along
    assert structure._plank_axis(img.transpose(1, 0, 2), ~hole.T, hole.T) == (None if along is None else 1 - along)


def _streaked_planks(size=160, width=12, seed=0):
    """Planks along x longer than the raster, each of its own shade, which changes slowly along
    it as wood's grain streaks do (a period of 400 cells, a random phase per plank), and noise."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[:size, :size]
    row = y // width
    phase = 2 * np.pi * rng.random(size // width + 1)[row]
    shade = 0.4 + 0.3 * rng.random(size // width + 1)[row] + 0.1 * np.sin(2 * np.pi * x / 400 + phase)
    img = shade[..., None] * np.array([1.0, 0.7, 0.45]) + 0.01 * rng.standard_normal((size, size, 1))
    img[y % width == 0] *= 0.4
    return img.astype(np.float32)


@pytest.mark.parametrize("transpose", [False, True])
def test_each_plank_keeps_its_own_shade_across_the_hole(transpose):
    """A copy from farther along a plank, or from another plank, brings another shade; the lines
    interpolated between each plank's visible ends follow its own."""
    truth = _streaked_planks()
    hole = _hole(160, 55, 105)
    inner = hole & (np.mgrid[:160, :160][0] % 12 != 0)  # off the seams
    if transpose:
        truth, hole, inner = truth.transpose(1, 0, 2), hole.T, inner.T
    got = structure_fill(np.where(hole[..., None], 0, truth), ~hole, hole)
    assert got.covered[hole].all() and got.detail == structure._PLANK_DETAIL
    assert got.along == (0 if transpose else 1) and got.lines[hole].all() and not got.lines[~hole].any()
    interpolated, copied = (float(np.abs(a - truth)[inner].mean()) for a in (got.image, got.shifts.image))
    assert interpolated < 0.5 * copied
    tiles = structure_fill(np.where(hole[..., None], 0, _tiles()), ~hole, hole)
    assert tiles.detail == 1.0 and tiles.along is None and tiles.lines is None


def _floor_with_lane_bend():
    """A plain floor with a short stretch of painted line (a lane's bend) far from a hole whose
    top rows were seen but repainted: two shifts copy equally seamless plain floor to every
    pixel beside the hole, the first also the line's stretch into the hole's inside."""
    img = np.full((40, 60, 3), [0.30, 0.35, 0.10], np.float32)
    img[2:10, 40:44] = [0.90, 0.80, 0.05]
    hole = np.zeros((40, 60), bool)
    hole[20:36, 10:31] = True
    repainted = np.zeros_like(hole)
    repainted[20:26, 10:31] = True  # the photograph shows plain floor there, under a highlight
    shifts = np.array([[-19, 22], [0, 25]])  # (-19, 22) puts the line at rows 21-28, columns 18-21
    return img, hole, repainted, shifts


def test_repainted_band_guides_the_copies_away_from_a_stray_line():
    """A line that ends in the repainted band is no cheaper than plain floor there: what the
    photograph shows in the band decides between copies the border cannot tell apart."""
    img, hole, repainted, shifts = _floor_with_lane_bend()
    guide = img * 1.2
    got = shift_map(img, ~hole, hole, shifts, guide=guide, guided=repainted)
    assert got.covered[hole].all()
    plain = np.broadcast_to(img[0, 0], got.image[hole].shape)
    np.testing.assert_allclose(got.image[hole], plain, atol=1e-6)  # no stretch of line in the hole


def test_guide_unlike_every_copy_prefers_none():
    """Where the photograph shows something unlike every copy (a chair's dark leg), every copy
    pays the same truncated cost: the labels are those without a guide."""
    img, hole, repainted, shifts = _floor_with_lane_bend()
    dark = np.full_like(img, -5.0)
    free = shift_map(img, ~hole, hole, shifts[::-1])
    guided = shift_map(img, ~hole, hole, shifts[::-1], guide=dark, guided=repainted)
    np.testing.assert_array_equal(guided.labels, free.labels)


def test_the_per_pixel_synthesis_copies_only_its_sources_while_every_known_pixel_constrains_it():
    rng = np.random.default_rng(2)
    image = (0.4 + 0.1 * rng.random((48, 64, 1))) * np.ones(3)
    hole = np.zeros((48, 64), bool)
    hole[18:30, 24:40] = True
    known = ~hole
    sources = known & (np.arange(64) < 32)[None, :]  # the left half only
    got = fill_structured(image.astype(np.float32), known, hole, SynthesisParams(), structure=False, sources=sources)
    origin = got.sources[hole]
    assert (origin[:, 0] >= 0).all()
    assert sources[origin[:, 0], origin[:, 1]].all()
    everywhere = fill_structured(image.astype(np.float32), known, hole, SynthesisParams(), structure=False)
    assert not sources[everywhere.sources[hole][:, 0], everywhere.sources[hole][:, 1]].all()
