"""Removal on the photo-textured ground-truth rooms (floors projected from real photographs,
windows, lamps), through the engine as the command line runs it (balanced, exact proxies):
    .venv/bin/python benchmarks/bench_photo_groundtruth.py [--scenes a,b] [--width 512] [--samples 32]
Prints a markdown table of `scenes.metrics.clean_removal_scores` for the scenes the fill's rules
were tuned on (`scenes.spec.PHOTO_SPECS`), and one for those placed after the rules were made
and never tuned on (`scenes.spec.HELD_OUT_SPECS`): light error (beside it the renders' noise
floor, `scenes.metrics.noise_floor`, as bench_removal gives it), fill structure, detail, fill
mean error, total (object + shadow error left); the mean error, total and detail of the truth's
own neighbouring patch pasted over the object (`scenes.metrics.neighbour_patch_scores`: a
plausible surface that is not the hidden one, under exactly the right light); the floor's paint
under the object over its paint around it (`scenes.printed.printed_level`: how far from the
level around the hole the truth's hidden floor lies, which no fill drawn from the panorama can
know unless it continues a structure, such as a band or a sunlit patch); far damage; bruise share
(hidden pixels darker than 0.8 x the clean surface's 1st percentile); the total our light alone
leaves (the truth's own pixels put in the hole: what no fill can take away); whether ours and
the neighbouring patch meet every bound (under the tables: on how many scenes each does); the
surfaces filled and the source of their exemplars where the report names it
(`filled_surfaces`); and the seconds.
The tables go to docs/results/bench_photo_groundtruth.md. out/photo_gt/<scene>.png shows the
panorama with the object, the truth without it and ours side by side, each above a crop around
the object three times enlarged, at the truth's exposure.
Renders are cached (scenes.render); the first run renders what is missing (a minute or two each).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from rendered import ground_truths, scene_list_arguments
from results import Table, write

OUT = Path(__file__).resolve().parents[1] / "out" / "photo_gt"


def comparison(images: list[np.ndarray], mask: np.ndarray, *, zoom: int = 3) -> np.ndarray:
    """(H', W', 3) uint8: the panoramas side by side, each above its crop around `mask` (padded
    by half its size, `zoom` times enlarged), tonemapped at the exposure of the last one."""
    from scenes.images import auto_exposure, tonemap

    exposure = auto_exposure(images[-1])
    rows, cols = np.nonzero(mask)
    pad_r, pad_c = max(8, np.ptp(rows) // 2), max(8, np.ptp(cols) // 2)
    r0, r1 = max(0, rows.min() - pad_r), min(mask.shape[0], rows.max() + pad_r + 1)
    c0, c1 = max(0, cols.min() - pad_c), min(mask.shape[1], cols.max() + pad_c + 1)
    panels = []
    for image in images:
        full = tonemap(image, exposure)
        crop = tonemap(image[r0:r1, c0:c1], exposure).repeat(zoom, axis=0).repeat(zoom, axis=1)
        width = max(full.shape[1], crop.shape[1])
        panel = np.full((full.shape[0] + crop.shape[0] + 4, width + 4, 3), 255, np.uint8)
        panel[:full.shape[0], :full.shape[1]] = full
        panel[full.shape[0] + 4:, :crop.shape[1]] = crop
        panels.append(panel)
    return np.concatenate(panels, axis=1)


def _sources(report: dict) -> str:
    """The filled surfaces, each with its exemplars' source and their share of the surface (and
    the cells of a band continued across the hole), or 'mean' where too little was seen to
    synthesise."""
    def source(f: dict) -> str:
        if not f["synthesised"]:
            return "mean"
        band = f" + a band across, {f['band_cells']} cells" if f["band_cells"] else ""
        return f"{f['exemplar']} {f['exemplar_share']:.0%}{band}"

    return ", ".join(f"{f['surface']}: {source(f)}" for f in report.get("filled_surfaces", [])) or "-"


def main() -> None:
    from scenes.spec import HELD_OUT_SPECS, PHOTO_SPECS

    args = scene_list_arguments(__doc__, ",".join([*PHOTO_SPECS, *HELD_OUT_SPECS]), width=512, samples=32)

    from addon.pipeline import remove_object
    from scenes import metrics
    from scenes.images import write_png
    from scenes.printed import printed_level

    OUT.mkdir(parents=True, exist_ok=True)
    columns = ["scene", "photo", "object", "light", "noise floor", "structure", "detail", "mean error", "total",
               "neighbour mean / total / detail", "printed under / around", "far damage", "bruise share",
               "light alone: total", "within bounds: ours / neighbour", "filled (source)", "seconds"]
    setting = f"{args.width}x{args.width // 2} at {args.samples} samples, balanced, exact proxies"
    titles = {False: "Tuned on", True: "Held out (placed after the rules were made, never tuned on)"}
    tables: dict[bool, Table] = {}  # each made when its first scene comes: a table prints its head then
    within = {held: {"scenes": 0, "ours": 0, "neighbour": 0} for held in titles}
    for gt in ground_truths(args):
        s = gt.spec
        r = remove_object(gt.scene, s.remove, quality="balanced")
        edit = gt.input + r.difference
        f = metrics.clean_removal_scores(gt.input, edit, gt.truth, gt.mask)
        n = metrics.neighbour_patch_scores(gt.input, gt.truth, gt.mask)
        light_alone = metrics.hidden_region_scores(gt.input, np.where(gt.mask[..., None], gt.truth, edit), gt.truth,
                                                   gt.mask)["object_shadow_ratio"]
        ours_in, neighbour_in = metrics.within_bounds(f), metrics.within_bounds(n)
        held = s.name in HELD_OUT_SPECS
        count = within[held]
        count["scenes"] += 1
        count["ours"] += ours_in
        count["neighbour"] += neighbour_in
        write_png(OUT / f"{s.name}.png", comparison([gt.input, gt.truth, edit], gt.mask))
        if held not in tables:
            tables[held] = Table(columns, title=f"{titles[held]}: {setting}")
        tables[held].row(
            s.name, s.room.floor.photo.source, s.removed_object().kind, f"{f['light']:.3f}",
            f"{metrics.noise_floor(gt.input, gt.truth, gt.mask):.3f}", f"{f['structure']:.3f}", f"{f['detail']:.2f}",
            f"{f['mean_error']:.3f}", f"{f['total']:.3f}",
            f"{n['mean_error']:.3f} / {n['total']:.3f} / {n['detail']:.2f}",
            f"{printed_level(s, gt.scene, gt.mask):.2f}", f"{f['far_damage']:.3f}", f"{f['bruise_share']:.3f}",
            f"{light_alone:.3f}", f"{'yes' if ours_in else 'no'} / {'yes' if neighbour_in else 'no'}",
            _sources(r.report), f"{r.report['seconds']['total']:.1f}")
    notes = [f"Bounds (issue 33): {metrics.bounds_text()}"]
    notes += [f"Within every bound, {'held out' if held else 'tuned on'}: ours on {c['ours']} of {c['scenes']} scenes, "
              f"the truth's neighbouring patch under the exact light on {c['neighbour']} of {c['scenes']}."
              for held, c in within.items() if c["scenes"]]
    write(*tables.values(), notes=notes)


if __name__ == "__main__":
    main()
