"""A wall's hole continued along its columns: against hand-made arrays (rows run upward)."""
import numpy as np

from addon.synthesis.texture import SynthesisParams
from addon.synthesis.wall_columns import column_sources, fill_columns, fill_wall


def _door_beside_wall(shape=(60, 80)):
    """A pale wall with a dark door (columns 40-59) and grain along the columns; the hole at the
    wall's foot (rows 0-24, columns 25-54), across the door's left edge, as a box before it hides."""
    rng = np.random.default_rng(0)
    image = np.full((*shape, 3), 0.8, np.float32)
    image[:, 40:60] = 0.05
    image *= (1 + 0.05 * rng.standard_normal(shape)).astype(np.float32)[..., None]
    hole = np.zeros(shape, bool)
    hole[:25, 25:55] = True
    return image, ~hole, hole


def test_the_door_edge_that_enters_the_hole_runs_on_down_to_the_wall_foot():
    image, known, hole = _door_beside_wall()
    got = fill_columns(image, known, hole)
    luma = got.image.mean(axis=2)
    assert (got.sources[hole] >= 0).all()
    assert luma[:25, 25:40].min() > 0.5  # the pale wall stays pale down to the foot
    assert luma[:25, 40:55].max() < 0.2  # the door stays dark down to the foot
    # no step where the fill meets the wall seen above it
    assert abs(float(luma[24, 25:55].mean() - luma[25, 25:55].mean())) < 0.05


def test_each_hole_pixel_takes_detail_from_its_own_column_mirrored_about_the_border():
    known = np.ones((20, 3), bool)
    known[:6, 1] = False  # the hole at the foot of the middle column
    known[14, 1] = False  # something else hides one cell above: the known run above the hole is 8 cells
    hole = ~known
    hole[14, 1] = False
    src = column_sources(known, hole)
    assert (src[:6, 1, 1] == 1).all()
    # rows 5, 4, ... copy rows 6, 7, ...: the first copied row meets the border without a step
    np.testing.assert_array_equal(src[:6, 1, 0], [11, 10, 9, 8, 7, 6])
    assert (src[~hole] == -1).all()
    # a hole taller than the known run beside it is reflected back within the run
    tall = np.zeros((20, 1), bool)
    tall[10:13] = True  # 3 known cells above a 10-cell hole at the foot
    src = column_sources(tall, ~tall & (np.arange(20) < 10)[:, None])
    assert set(src[:10, 0, 0]) == {10, 11, 12}


def test_a_hole_between_two_seen_stretches_is_interpolated_between_them():
    image = np.zeros((30, 4, 3), np.float32)
    image[:10] = 0.2
    image[20:] = 0.6
    known = np.ones((30, 4), bool)
    known[10:20] = False
    got = fill_columns(image, known, ~known)
    column = got.image[10:20, 0, 0]
    assert np.all(np.diff(column) > 0) and column[0] > 0.2 and column[-1] < 0.6


def test_columns_that_show_nothing_are_synthesised_from_the_wall():
    image, known, hole = _door_beside_wall()
    hole[:, 2:6] = True  # columns hidden from top to bottom
    known = ~hole
    got = fill_wall(image, known, hole, SynthesisParams(neighbourhood=5, levels=2, generations=1))
    assert np.isfinite(got.image[hole]).all()
    assert (got.image[:, 2:6].mean(axis=2) > 0.5).all()  # the pale wall around them, not the door
    # a source is kept only where the synthesis copied a seen pixel: its photograph detail is read there
    src = got.sources[:, 2:6][got.sources[:, 2:6, 0] >= 0]
    assert len(src) and known[src[:, 0], src[:, 1]].all()
