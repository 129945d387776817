"""Filling the floor a lid hides: reflectance synthesised on the plane raster, not blurred."""
import numpy as np

from addon.geometry import latlong
from addon.synthesis import plane_fill
from addon.synthesis.plane_fill import FillOptions, HiddenPlane, PanoramaMaps, PanoramaReflectance, fill_surface
from addon.synthesis.texture import SynthesisParams
from tests.engine.geometry.test_planeraster import maps

WIDTH = 512


def checker_rho(points, period=0.2):
    """Reflectance of a floor checker of 0.1 m squares: 0.7 and 0.2 in every channel."""
    k = (np.floor(points[..., 0] / (period / 2)) + np.floor(points[..., 1] / (period / 2))) % 2
    return np.where(k[..., None] == 0, 0.7, 0.2) * np.ones(3)


def setup():
    s_with, d_with, s_without, d_without, hidden = maps(WIDTH)
    panorama_maps = PanoramaMaps(s_with, d_with, s_without, d_without, hidden)
    points = latlong.pixel_directions(WIDTH, WIDTH // 2) * d_without[..., None]
    rho = checker_rho(points)
    valid = (s_with == 0) & ~hidden
    revealed = hidden & (s_without == 0)
    floor = HiddenPlane(surface=0, normal=np.array([0, 0, 1.0]), points=points[revealed])
    return panorama_maps, rho, valid, floor, checker_rho(points[revealed])


def _options(seed: int = 0) -> FillOptions:
    return FillOptions(cell=0.02, margin=1.5, synthesis=SynthesisParams(), seed=seed)


def test_the_fill_continues_the_checker_under_the_lid():
    panorama_maps, rho, valid, floor, truth = setup()
    got = fill_surface(PanoramaReflectance(rho, valid, panorama_maps), floor, _options())
    points = floor.points
    assert got.synthesised and got.known_cells > 1000 and got.hole_cells >= len(points) // 4
    assert np.isfinite(got.rho).all() and (got.rho >= 0).all()
    y = got.rho[:, 0]
    # Texture, not a blur: most values are near one of the two reflectances, both present.
    assert np.mean((np.abs(y - 0.7) < 0.15) | (np.abs(y - 0.2) < 0.15)) > 0.7
    assert 0.25 < np.mean(y > 0.45) < 0.75
    assert abs(y.mean() - truth[:, 0].mean()) < 0.12


def test_the_same_seed_fills_the_same_and_the_mean_stands_in_for_a_tiny_exemplar():
    panorama_maps, rho, valid, floor, _ = setup()
    panorama = PanoramaReflectance(rho, valid, panorama_maps)
    a, b = fill_surface(panorama, floor, _options(seed=3)), fill_surface(panorama, floor, _options(seed=3))
    assert np.array_equal(a.rho, b.rho)
    # With all but a handful of floor pixels invalid, there is nothing to learn the texture from.
    few = np.zeros_like(valid)
    few[np.argwhere(valid)[:10].T.tolist()] = True
    c = fill_surface(PanoramaReflectance(rho, few, panorama_maps), floor, _options())
    assert not c.synthesised
    assert np.allclose(c.rho, c.rho[0]) and np.isfinite(c.rho).all()


def test_a_synthesised_fill_keeps_the_photographs_fine_detail():
    """A plain floor whose pixels carry independent grain: the per-pixel synthesis on the
    raster (cells of about a pixel) averages some of it away; the photograph's own detail,
    read at each cell's source, brings the fill's spread back to the floor's."""
    panorama_maps, _, valid, floor, _ = setup()
    grain = 0.5 + 0.05 * np.random.default_rng(0).standard_normal((WIDTH // 2, WIDTH, 1)) * np.ones(3)
    options = FillOptions(cell=0.01, margin=1.5, synthesis=SynthesisParams(), structure=False)
    got = fill_surface(PanoramaReflectance(grain, valid, panorama_maps), floor, options)
    assert got.synthesised and got.structured == 0
    assert 0.8 * 0.05 < got.rho[:, 0].std() < 1.25 * 0.05
    assert abs(got.rho[:, 0].mean() - 0.5) < 0.01


def test_thin_dark_lines_at_the_shifted_copies_sources_add_no_darker_detail_than_the_photograph_shows():
    """Lines a pixel wide across a grainy floor, often enough to repeat (chair legs printed on
    it, thinner than a cell): the raster holds them blurred, the photograph sharp, and the detail
    read at a shifted copy's source is their difference. Added in full, a copy whose cell already
    took a line went darker than anything the photograph shows, below zero; the detail is kept
    within the grain's spread."""
    panorama_maps, _, valid, floor, _ = setup()
    legs = 0.5 + 0.05 * np.random.default_rng(0).standard_normal((WIDTH // 2, WIDTH, 1)) * np.ones(3)
    legs[:, ::16] = 0.05
    options = FillOptions(cell=0.01, margin=1.5, synthesis=SynthesisParams())
    got = fill_surface(PanoramaReflectance(legs, valid, panorama_maps), floor, options)
    assert got.synthesised and got.structured > 0 and got.rho.min() > 0.05
    assert abs(got.rho[:, 0].mean() - legs[valid, 0].mean()) < 0.03


def plank_rho(points, width=0.06):
    """Planks along x, 6 cm wide, each of its own shade, with a dark seam along one side."""
    k = np.floor(points[..., 1] / width)
    shade = np.where(points[..., 1] / width - k < 0.15, 0.12, 0.35 + 0.3 * ((k * 0.618034) % 1.0))
    return shade[..., None] * np.array([1.0, 0.8, 0.6])


def test_the_planks_lines_keep_their_contrast_through_the_lookups(monkeypatch):
    """The lines interpolated along the planks are looked up from the raster bilinearly, which
    blurs their seams across; sharpened across them first, the fill's contrast between seams
    and planks comes nearer the truth's, its lines still where the truth's are. (Where the
    planks' profile is found it gives the seams instead: here it is not looked for.)"""
    monkeypatch.setattr(plane_fill, "_plank_profile", lambda *_: None)
    panorama_maps, _, valid, floor, _ = setup()
    points = latlong.pixel_directions(WIDTH, WIDTH // 2) * panorama_maps.distance_without[..., None]
    panorama = PanoramaReflectance(plank_rho(points), valid, panorama_maps)
    planks = HiddenPlane(surface=0, normal=floor.normal, points=floor.points, along=np.array([1.0, 0.0, 0.0]))
    truth = plank_rho(floor.points)[:, 0]

    def slope_and_correlation(gain):
        monkeypatch.setattr(plane_fill, "_LINE_SHARPENING", gain)
        got = fill_surface(panorama, planks, FillOptions(cell=0.01, margin=1.5, synthesis=SynthesisParams()))
        assert got.structured == got.hole_cells
        a, b = got.rho[:, 0] - got.rho[:, 0].mean(), truth - truth.mean()
        return (a * b).sum() / (b * b).sum(), np.corrcoef(a, b)[0, 1]

    (slope_plain, correlation_plain), (slope, correlation) = slope_and_correlation(0.0), slope_and_correlation(2.0)
    assert slope_plain + 0.05 < slope < 1.0 and correlation > correlation_plain - 0.02


def thin_seam_rho(points, width=0.07, seam=0.008):
    """Planks along x, 7 cm wide and of one shade, their seams 8 mm wide: thinner than a pixel,
    seen in a pixel only where its centre falls on them (as a point-sampled render sees them)."""
    on_seam = np.mod(points[..., 1], width) < seam
    return np.where(on_seam, 0.1, 0.5)[..., None] * np.array([1.0, 0.8, 0.6])


def test_seams_thinner_than_a_pixel_darken_the_hidden_pixels_on_them(monkeypatch):
    """Interpolated along the planks, a seam thinner than a pixel comes out a faint line at the
    raster's resolution; folded over the planks' width, the visible floor resolves it, and the
    fill darkens the hidden pixels whose centres fall on a seam, as the photograph would."""
    panorama_maps, _, valid, floor, _ = setup()
    points = latlong.pixel_directions(WIDTH, WIDTH // 2) * panorama_maps.distance_without[..., None]
    panorama = PanoramaReflectance(thin_seam_rho(points), valid, panorama_maps)
    planks = HiddenPlane(surface=0, normal=floor.normal, points=floor.points, along=np.array([1.0, 0.0, 0.0]))
    truth = thin_seam_rho(floor.points)[:, 0]
    options = FillOptions(cell=0.01, margin=1.5, synthesis=SynthesisParams())
    profiled = fill_surface(panorama, planks, options).rho[:, 0]
    monkeypatch.setattr(plane_fill, "_plank_profile", lambda *_: None)
    interpolated = fill_surface(panorama, planks, options).rho[:, 0]
    on_seam = truth < 0.3
    assert 10 < on_seam.sum() < 0.2 * len(truth)
    correlation = np.corrcoef(profiled, truth)[0, 1]
    assert correlation > 0.9 and correlation > np.corrcoef(interpolated, truth)[0, 1] + 0.3
    assert profiled[on_seam].mean() < 0.25 and abs(profiled.mean() / truth.mean() - 1) < 0.05


def test_a_lane_between_two_floors_runs_on_under_the_lid_unless_structure_is_off():
    """A yellow lane between a green floor and a brown one crosses the hidden floor: with the
    structure-aware fill it is continued as a strip (`crossing`), the floors on its sides each
    their own; without it, the material's fill alone decides."""
    panorama_maps, _, valid, floor, _ = setup()
    s_with, d_with = panorama_maps.surface_with, panorama_maps.distance_with
    centre = floor.points.mean(axis=0)
    direction = np.array([np.cos(0.4), np.sin(0.4), 0.0])

    def lane_rho(points):
        across = (points - centre) @ np.array([-direction[1], direction[0], 0.0])
        green, yellow, brown = np.array([0.10, 0.16, 0.06]), np.array([0.55, 0.42, 0.05]), np.array([0.16, 0.11, 0.07])
        return np.where((across < -0.03)[..., None], green, np.where((across > 0.03)[..., None], brown, yellow))

    points = latlong.pixel_directions(WIDTH, WIDTH // 2) * d_with[..., None]
    panorama = PanoramaReflectance(lane_rho(points), valid & (s_with == 0), panorama_maps)
    options = FillOptions(cell=0.01, margin=1.5, synthesis=SynthesisParams())
    got = fill_surface(panorama, floor, options)
    assert got.band_cells > 0
    truth = lane_rho(floor.points)
    error = np.abs(got.rho - truth).sum(axis=1) / truth.sum(axis=1)
    assert np.median(error) < 0.1
    off = fill_surface(panorama, floor, FillOptions(cell=0.01, margin=1.5, synthesis=SynthesisParams(),
                                                    structure=False))
    assert off.band_cells == 0


def test_the_objects_shadow_left_beside_the_lid_is_lifted_to_the_floors_level():
    """The relighting left a soft shadow darker than the floor along one side of the lid (a
    proxy shallower than the object): the fill does not continue it, and the surface's pixels
    there are lifted to the floor's level; nothing far from it is."""
    panorama_maps, _, valid, floor, _ = setup()
    points = latlong.pixel_directions(WIDTH, WIDTH // 2) * panorama_maps.distance_without[..., None]
    grain = 1 + 0.03 * np.random.default_rng(5).standard_normal((WIDTH // 2, WIDTH, 1))
    beyond = points[..., 1] - 1.2  # past the hidden square's far side
    shade = np.where((beyond > 0) & (np.abs(points[..., 0] - 1.0) < 0.2), np.clip(0.45 + beyond / 0.3 * 0.55, 0, 1), 1)
    rho = np.array([0.45, 0.30, 0.18]) * grain * shade[..., None]
    got = fill_surface(PanoramaReflectance(rho, valid, panorama_maps), floor,
                       FillOptions(cell=0.01, margin=1.5, synthesis=SynthesisParams()))
    assert got.lift is not None and got.lifted_pixels > 0
    level = 0.45 * 0.2126 + 0.30 * 0.7152 + 0.18 * 0.0722
    dark = valid & (shade < 0.6)
    assert dark.sum() > 30
    lifted = (rho[dark] * got.lift[dark, None]) @ np.array([0.2126, 0.7152, 0.0722])
    assert abs(np.median(lifted) / level - 1) < 0.1
    far = valid & (np.hypot(points[..., 0] - 1.0, points[..., 1] - 1.0) > 0.8)
    assert np.all(got.lift[far] == 1.0)
    # the fill is the floor's level, not the shadow's
    assert abs(np.median(got.rho @ np.array([0.2126, 0.7152, 0.0722])) / level - 1) < 0.1
