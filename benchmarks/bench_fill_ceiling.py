"""What fills interpolated along the planks from the visible floor reach in structure on plank
floors, measured on the truth itself (the render without the object: no lighting estimate, no
reflectance, only what the probe sees of the floor). No ceiling for ours: these interpolate the
pixels seen at the hole's ends, whose seams (thinner than a pixel) are seen at other pixels than
the hidden ones, where our planks' profile draws them at the hidden pixels' own positions:
    .venv/bin/python benchmarks/bench_fill_ceiling.py [--scenes a,b] [--width 1024] [--samples 16]
For each of the object's pixels whose ray meets the floor, the floor is followed along the
planks (the scenes' planks run along x), both ways in 5 mm steps, to the nearest point the probe
sees (its pixel is not the object's). Three fills of the truth's own pixels, scored as
`bench_fill_groundtruth` scores ours (`scenes.metrics.structure_correlation`) over those floor
pixels, the truth kept on the object's other pixels:
- copy: the truth at the nearer of the two points (a shift map's best copy, per pixel);
- interpolation: linear between the two, each the mean over 3 cm beyond it (as `lines`);
- the same with grain: plus the truth's pixel detail (the pixel minus its 3x3 mean) at the nearer
  point's pixel, as our fill adds its copies' detail to the lines, scaled to a detail ratio of
  1: what the interpolation scores once it carries grain at the photograph's level, as the
  detail bound asks;
- the interpolation sharpened: plus its own pixel detail (the pixel minus its 3x3 mean, an
  unsharp mask), scaled to a detail ratio of 1, as our fill sharpens its lines across the
  planks: detail that lies where the interpolation's own edges do.
Each with its detail ratio (`scenes.metrics.detail_ratio`) over those pixels, as ours.
The last columns are our removal's fill over the same pixels (balanced, exact proxies; the truth
kept elsewhere, as above) and a second render of the truth (another seed: its noise alone;
`rendered.second_render_structure`).
Renders are cached (scenes.render); the first run renders what is missing (minutes each).
"""
from __future__ import annotations

import numpy as np

from rendered import ground_truths, scene_list_arguments, second_render_structure
from results import Table, write
from scenes.spec import SceneSpec

SCENES = "demo,stool,warm_cylinder,oak_chair,walnut_crate,far_pouf"
STEP = 0.005  # metres along the planks
REACH = 2.0  # metres searched each way
ENDS = 0.03  # metres averaged beyond each visible end


def _floor_points(spec: SceneSpec, width: int, height: int, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The object's pixels whose ray meets the floor inside the room, and those points
    relative to the probe."""
    from addon.geometry import latlong

    d = latlong.pixel_directions(width, height)
    down = d[..., 2] < -1e-3
    t = np.where(down, -spec.probe[2] / np.where(down, d[..., 2], -1.0), 0.0)
    p = d * t[..., None]
    world = p + np.asarray(spec.probe)
    lo, hi = np.asarray(spec.room.lo) + 0.01, np.asarray(spec.room.hi) - 0.01
    inside = (world[..., 0] > lo[0]) & (world[..., 0] < hi[0]) & (world[..., 1] > lo[1]) & (world[..., 1] < hi[1])
    floor = mask & down & inside
    return floor, p[floor]


def _nearest_seen(points: np.ndarray, sign: int, mask: np.ndarray, spec: SceneSpec) -> tuple[np.ndarray, np.ndarray]:
    """(N,) the distance along x to the nearest point the probe sees (inf where none within
    REACH), and (N, 3) that point."""
    from addon.geometry import latlong

    h, w = mask.shape
    steps = sign * STEP * np.arange(1, int(REACH / STEP) + 1)
    moved = points[None] + steps[:, None, None] * np.array([1.0, 0.0, 0.0])
    u, v = latlong.direction_to_uv(moved)
    row, col = latlong.uv_to_pixel(u, v, w, h)
    x = moved[..., 0] + spec.probe[0]
    seen = ~mask[row, col] & (x > spec.room.lo[0]) & (x < spec.room.hi[0])
    first = seen.argmax(axis=0)
    found = seen[first, np.arange(len(points))]
    distance = np.where(found, np.abs(steps[first]), np.inf)
    return distance, moved[first, np.arange(len(points))]


def _end_mean(points: np.ndarray, sign: int, truth: np.ndarray) -> np.ndarray:
    from addon.geometry import planeraster

    valid = np.ones(truth.shape[:2], bool)
    offsets = sign * np.arange(0.0, ENDS + 1e-9, STEP)
    return np.mean([planeraster.sample_points(points + o * np.array([1.0, 0.0, 0.0]), truth, valid)[0]
                    for o in offsets], axis=0)


def _edited(values: np.ndarray, truth: np.ndarray, floor: np.ndarray, reached: np.ndarray) -> np.ndarray:
    """The truth with its `floor` pixels replaced by `values` where `reached`."""
    edit = truth.copy()
    edit[floor] = np.where(reached[:, None], values, truth[floor])
    return edit


def _scored(values: np.ndarray, truth: np.ndarray, floor: np.ndarray, reached: np.ndarray) -> str:
    """Structure and detail ratio of `_edited` over the floor pixels, as a table's cell."""
    from scenes import metrics

    edit = _edited(values, truth, floor, reached)
    return f"{metrics.structure_correlation(edit, truth, floor):.3f}, {metrics.detail_ratio(edit, truth, floor):.2f}"


def _with_grain(values: np.ndarray, grain: np.ndarray, truth: np.ndarray, floor: np.ndarray,
                reached: np.ndarray) -> np.ndarray:
    """`values` plus `grain` scaled to a detail ratio of 1 over the floor pixels. The ratio
    squared is a quadratic in the scale (the grain may correlate with the values' own detail):
    fitted through the scales -1, 0 and 1, its root at 1 taken (the larger one)."""
    from scenes import metrics

    def squared(scale: float) -> float:
        return metrics.detail_ratio(_edited(values + scale * grain, truth, floor, reached), truth, floor) ** 2

    below, bare, full = squared(-1.0), squared(0.0), squared(1.0)
    a, b, c = (full + below) / 2 - bare, (full - below) / 2, bare - 1.0
    scale = (-b + np.sqrt(max(b * b - 4 * a * c, 0.0))) / (2 * a) if a > 1e-12 else -c / max(b, 1e-12)
    return values + max(scale, 0.0) * grain


def _grain(points: np.ndarray, truth: np.ndarray) -> np.ndarray:
    """(N, 3) the truth's pixel detail (the pixel minus its 3 x 3 mean) at the pixels of `points`."""
    from addon.geometry import latlong
    from scenes import metrics

    h, w = truth.shape[:2]
    row, col = latlong.uv_to_pixel(*latlong.direction_to_uv(points), w, h)
    return (truth - metrics.box_blur3(truth))[row, col]


def main() -> None:
    args = scene_list_arguments(__doc__, SCENES)

    from addon.geometry import planeraster
    from addon.pipeline import remove_object
    from scenes import metrics

    table = Table(["scene", "floor pixels", "median distance to seen floor m", "copy", "interpolation",
                   "interpolation with grain", "interpolation sharpened", "ours", "second render"],
                  title=f"{args.width}x{args.width // 2} at {args.samples} samples, structure and detail ratio over"
                        " the object's floor pixels")
    for gt in ground_truths(args):
        s, truth, mask = gt.spec, gt.truth, gt.mask
        if s.room.floor.pattern != "planks" or s.world_rotation_z:
            raise SystemExit(f"{s.name}: planks along x in an unrotated world only")
        floor, points = _floor_points(s, mask.shape[1], mask.shape[0], mask)
        (after, at_after), (before, at_before) = (_nearest_seen(points, sign, mask, s) for sign in (1, -1))
        valid = np.ones(mask.shape, bool)
        nearer = np.where((after <= before)[:, None], at_after, at_before)
        copy = planeraster.sample_points(nearer, truth, valid)[0]
        both = np.isfinite(after) & np.isfinite(before)
        share = np.where(both, before / np.where(both, after + before, 1.0), np.isfinite(after).astype(float))
        interpolated = (share[:, None] * _end_mean(at_after, 1, truth)
                        + (1 - share[:, None]) * _end_mean(at_before, -1, truth))
        reached = np.isfinite(np.minimum(after, before))
        grained = _with_grain(interpolated, _grain(nearer, truth), truth, floor, reached)
        bare = _edited(interpolated, truth, floor, reached)
        sharpened = _with_grain(interpolated, (bare - metrics.box_blur3(bare))[floor], truth, floor, reached)
        r = remove_object(gt.scene, s.remove, quality="balanced")
        ours = (gt.input + r.difference)[floor]
        table.row(s.name, int(floor.sum()), f"{np.median(np.minimum(after, before)[reached]):.2f}",
                  _scored(copy, truth, floor, reached), _scored(interpolated, truth, floor, reached),
                  _scored(grained, truth, floor, reached), _scored(sharpened, truth, floor, reached),
                  _scored(ours, truth, floor, np.ones_like(reached)), f"{second_render_structure(gt, floor):.3f}")
    write(table)


if __name__ == "__main__":
    main()
