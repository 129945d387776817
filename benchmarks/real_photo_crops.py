"""Crops of real photographs before and after the removal, next to PatchMatch: the hotel room's
armchair (Blender's interior.exr) and a red bench in the lobby (../shared/real_photos/lobby.exr).

    .venv/bin/python benchmarks/real_photo_crops.py [--scenes hotel,lobby]

Each scene is built from an empty one as a user would model it by eye: the room by Match Room
from floor-corner clicks (the hotel's committed click file, tests/data/rooms/interior.json; for
the lobby, corners of a rough box read off the panorama), the object a box of a size guessed by
eye, its near bottom edge placed where the photograph shows the object's feet touch the floor.
The .blend is saved under out/real_photo_crops/<scene>/ and the removal runs through the
command line exactly as a user runs it (`python -m addon.cli remove SCENE.blend --object NAME
--align --out DIR`, balanced, then again at `--quality draft`, the preset a first look takes).
PatchMatch (the benchmark environment .venv-bench, which
`./dev bench-synthesis` sets up) then fills the same panorama, tone-mapped to 8 bits as a 2D
tool gets a photograph, over a generous mask: the pixels near the object whose colour our run
changed by more than 35 % at balanced, dilated, holes filled. Writes
docs/images/real_<scene>_<object>.png (photograph | ours, balanced | ours, draft | PatchMatch) and
docs/results/real_photo_crops.md (the commands, seconds and the report's warnings).
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from results import Table, write

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
OUT = ROOT / "out" / "real_photo_crops"
BENCH_PYTHON = ROOT / ".venv-bench" / "bin" / "python"
CHANGED = 0.35  # relative change of colour that puts a pixel into PatchMatch's mask
CROP_HEIGHT = 400  # pixels each crop is enlarged to, about


@dataclass(frozen=True)
class PhotoScene:
    """A real panorama, its room as clicks and the object as a box modelled by eye: `feet` are
    the pixels (x, y) where the photograph shows the ends of the object's near bottom edge on
    the floor; the box is `size` = (along that edge, away from the probe, up) metres."""

    name: str
    panorama: str
    clicks: dict
    object_name: str
    feet: tuple[tuple[float, float], tuple[float, float]]
    size: tuple[float, float, float]


def _interior() -> str:
    import bpy

    return str(Path(bpy.utils.system_resource('DATAFILES')) / "studiolights" / "world" / "interior.exr")


def _scenes() -> dict[str, PhotoScene]:
    hotel_clicks = json.loads((ROOT / "tests" / "data" / "rooms" / "interior.json").read_text())
    # The lobby's floor is far larger than its walls are clear: the far wall with the doors ~10 m
    # ahead, the stairs ~4 m to the right, the green wall ~6 m behind; a box room at 1.6 m.
    lobby_clicks = {"width": 512, "height": 256, "camera_height": 1.6, "manhattan": True,
                    "floor": [[284.3, 139.3], [223.9, 139.1], [48.0, 144.7], [466.7, 145.1]]}
    return {
        # the armchair's front feet; a 0.68 x 0.7 x 0.8 m box (issue 33)
        "hotel": PhotoScene("hotel", _interior(), hotel_clicks, "Armchair",
                            ((452.0, 419.0), (536.0, 399.0)), (0.68, 0.7, 0.8)),
        # the nearer red bench's dark base: its left and right bottom corners
        "lobby": PhotoScene("lobby", str(ROOT.parent / "shared" / "real_photos" / "lobby.exr"), lobby_clicks,
                            "Bench", ((222.0, 175.0), (304.0, 203.5)), (2.1, 0.65, 0.43)),
    }


def box_corners(scene: PhotoScene, probe: np.ndarray) -> np.ndarray:
    """The object's box (8, 3): bottom four counter-clockwise, then the top four; the floor at z = 0."""
    from addon.roommatch.projection import click_directions

    clicks = scene.clicks
    d = click_directions(np.array(scene.feet), clicks["width"], clicks["height"])
    feet = probe[:2] + d[:, :2] * (probe[2] / -d[:, 2:3])
    along = (feet[1] - feet[0]) / np.linalg.norm(feet[1] - feet[0])
    away = np.array([-along[1], along[0]])
    middle = feet.mean(axis=0)
    if away @ (middle - probe[:2]) < 0:
        away = -away
    width, depth, height = scene.size
    near = middle - along * width / 2, middle + along * width / 2
    ring = np.array([near[0], near[1], near[1] + away * depth, near[0] + away * depth])
    (ax, ay), (bx, by) = ring[1] - ring[0], ring[2] - ring[1]
    if ax * by - ay * bx < 0:
        ring = ring[::-1]
    return np.concatenate([np.c_[ring, np.zeros(4)], np.c_[ring, np.full(4, height)]])


def build(scene: PhotoScene, folder: Path) -> tuple[Path, np.ndarray]:
    """Save the scene (room, probe centre, the object's box) as folder/<name>.blend, with the room's
    diagnostics picture (the box drawn in); the .blend's path and the box's corners relative to the
    probe centre."""
    import bpy

    from addon.blender import reader, room_builder
    from addon.io.exr import write_png
    from addon.roommatch import clicks as click_file
    from addon.roommatch.diagnostics import room_picture

    bpy.ops.wm.read_factory_settings(use_empty=True)
    bscene = bpy.context.scene
    room_builder.show_panorama(bscene, scene.panorama)
    clicks = click_file.from_dict(scene.clicks)
    room = room_builder.match_room(bscene, clicks)
    corners = box_corners(scene, room.probe)
    room_builder.box_object(bscene, scene.object_name, corners)
    folder.mkdir(parents=True, exist_ok=True)
    write_png(folder / "room_diagnostics.png",
              room_picture(reader.panorama_pixels(bscene), room, clicks, boxes=(corners,)))
    path = folder / f"{scene.name}.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return path, corners - room.probe


def remove_command(blend: Path, object_name: str, out: Path, *, quality: str = "balanced") -> list[str]:
    preset = [] if quality == "balanced" else ["--quality", quality]
    return [".venv/bin/python", "-m", "addon.cli", "remove", str(blend.relative_to(ROOT)), "--object", object_name,
            "--align", *preset, "--out", str(out.relative_to(ROOT))]


def luminance(image: np.ndarray) -> np.ndarray:
    return image @ np.array([0.2126, 0.7152, 0.0722])


def patchmatch_mask(before: np.ndarray, after: np.ndarray, near: tuple[slice, slice]) -> np.ndarray:
    """The object's region as our run changed it: the pixels within `near` whose colour moved by
    more than CHANGED of its own size, dilated by a 170th of the width (6 px at 1024 wide), the
    part joined to the middle of `near`, its holes filled (a fill that happens to match the object
    somewhere still leaves that pixel to PatchMatch)."""
    from addon.geometry.latlong import dilate

    moved = np.linalg.norm(after - before, axis=-1) / np.maximum(np.linalg.norm(before, axis=-1), 1e-6)
    changed = np.zeros(moved.shape, bool)
    changed[near] = moved[near] > CHANGED
    changed = dilate(changed, max(2, before.shape[1] // 170))
    middle = np.zeros_like(changed)
    rows, cols = near
    h, w = rows.stop - rows.start, cols.stop - cols.start
    middle[rows.start + h // 4:rows.stop - h // 4, cols.start + w // 4:cols.stop - w // 4] = True
    region = _grown(changed & middle, changed)
    outside = np.zeros_like(region)
    outside[[0, -1], :] = outside[:, [0, -1]] = True
    return ~_grown(outside & ~region, ~region)


def _grown(seed: np.ndarray, allowed: np.ndarray) -> np.ndarray:
    """The pixels of `allowed` joined to `seed` (4-neighbours, within the image)."""
    grown = seed & allowed
    while True:
        step = grown.copy()
        step[1:] |= grown[:-1]
        step[:-1] |= grown[1:]
        step[:, 1:] |= grown[:, :-1]
        step[:, :-1] |= grown[:, 1:]
        step &= allowed
        if (step == grown).all():
            return grown
        grown = step


def display(image: np.ndarray, white: float) -> np.ndarray:
    """8-bit display-referred: scaled so `white` is 1, clipped, gamma 2.2."""
    return (np.clip(np.nan_to_num(image) / white, 0.0, 1.0) ** (1 / 2.2) * 255 + 0.5).astype(np.uint8)


def padded_box(mask: np.ndarray, *, pad_share: float) -> tuple[slice, slice]:
    """The mask's bounding box grown on each side by `pad_share` of its longer side, clipped."""
    ys, xs = np.nonzero(mask)
    pad = int(max(np.ptp(ys), np.ptp(xs)) * pad_share) + 4
    return (slice(max(ys.min() - pad, 0), min(ys.max() + pad + 1, mask.shape[0])),
            slice(max(xs.min() - pad, 0), min(xs.max() + pad + 1, mask.shape[1])))


def silhouette_box(corners: np.ndarray, width: int, height: int) -> np.ndarray:
    """(H, W) bool: the bounding box of where the corners (relative to the probe centre) land in
    the panorama."""
    from addon.roommatch.projection import project

    xy = project(corners, width, height)
    mask = np.zeros((height, width), bool)
    x0, y0 = np.floor(xy.min(axis=0)).astype(int)
    x1, y1 = np.ceil(xy.max(axis=0)).astype(int)
    mask[max(y0, 0):y1 + 1, max(x0, 0):x1 + 1] = True
    return mask


def run_patchmatch(image8: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, float]:
    """PatchMatch's fill of `mask` in the 8-bit `image8` (in .venv-bench, a subprocess), and its seconds."""
    if not BENCH_PYTHON.exists():
        raise SystemExit(f"no {BENCH_PYTHON.relative_to(ROOT)}: run `./dev bench-synthesis --help` once to set it up")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "patchmatch.npz"
        np.savez(path, image=image8, mask=mask)
        subprocess.run([str(BENCH_PYTHON), __file__, "--patchmatch", str(path)], check=True, cwd=ROOT)
        with np.load(path) as done:
            return done["filled"], float(done["seconds"])


def patchmatch_step(path: str) -> None:
    """Inside .venv-bench: fill the npz's image over its mask (patch radius 3, seed 0, as in
    benchmarks/bench_synthesis.py) and write it back."""
    import patchmatch

    with np.load(path) as data:
        image, mask = data["image"], data["mask"]
    patchmatch.set_random_seed(0)
    started = time.perf_counter()
    filled = patchmatch.inpaint(image, mask.astype(np.uint8) * 255, patch_size=3)
    np.savez(path, filled=filled, seconds=time.perf_counter() - started)


def side_by_side(panels: list[np.ndarray]) -> np.ndarray:
    scale = max(1, round(CROP_HEIGHT / panels[0].shape[0]))
    gap = np.full((panels[0].shape[0], 3, 3), 255, np.uint8)
    row = np.concatenate([x for p in panels for x in (p, gap)][:-1], axis=1)
    return row.repeat(scale, 0).repeat(scale, 1)


def crops(scene: PhotoScene, table: Table) -> list[str]:
    """Build, remove at balanced and at draft, fill with PatchMatch, write the picture; one table
    row; the notes (the commands, the balanced report's warnings and alignment)."""
    folder = OUT / scene.name
    blend, corners = build(scene, folder)
    runs = {quality: _removed(blend, scene.object_name, folder / out, quality=quality)
            for quality, out in (("balanced", "removed"), ("draft", "removed_draft"))}
    (command, wall, report), (draft_command, draft_wall, _) = runs["balanced"], runs["draft"]
    image, mask_pixels, pm_seconds = compare(scene, corners, folder / "removed" / "edited.exr",
                                             folder / "removed_draft" / "edited.exr")
    seg, align = report.get("segmentation", {}), report.get("alignment", {})
    table.row(scene.name, scene.object_name, f"{wall:.1f}", f"{report['seconds']['total']:.1f}",
              f"{report['seconds'].get('local', 0.0):.1f}", f"{draft_wall:.1f}", seg.get("agreement", "-"),
              "applied" if align.get("applied") else "left as modelled", mask_pixels, f"{pm_seconds:.1f}",
              f"[{image.name}](../images/{image.name})")
    return [f"![{scene.name}: photograph, ours (balanced), ours (draft), PatchMatch](../images/{image.name})",
            f"{scene.name}: `{' '.join(command)}`", f"{scene.name}, draft: `{' '.join(draft_command)}`"] \
        + [f"{scene.name} warning: {w}" for w in report["warnings"]] \
        + ([f"{scene.name} alignment: {align['message']}"] if align.get("message") else [])


def _removed(blend: Path, object_name: str, out: Path, *, quality: str) -> tuple[list[str], float, dict]:
    """The removal through the command line: its command, wall seconds and report."""
    command = remove_command(blend, object_name, out, quality=quality)
    started = time.perf_counter()
    subprocess.run(command, check=True, cwd=ROOT)
    return command, time.perf_counter() - started, json.loads((out / "report.json").read_text())


def compare(scene: PhotoScene, corners: np.ndarray, edited: Path, draft: Path) -> tuple[Path, int, float]:
    """PatchMatch's fill of the region our balanced run changed, and the picture photograph |
    ours, balanced | ours, draft | PatchMatch; its path, the mask's pixels and PatchMatch's seconds."""
    from addon.io.exr import read_exr, write_png

    before, after, after_draft = read_exr(scene.panorama), read_exr(edited), read_exr(draft)
    height, width = before.shape[:2]
    mask = patchmatch_mask(before, after, padded_box(silhouette_box(corners, width, height), pad_share=0.25))
    box = padded_box(mask, pad_share=0.25)
    white = float(np.percentile(luminance(before)[box][~mask[box]], 97))
    filled, seconds = run_patchmatch(display(before, white), mask)
    image = ROOT / "docs" / "images" / f"real_{scene.name}_{scene.object_name.lower()}.png"
    write_png(image, side_by_side([display(x[box], white) for x in (before, after, after_draft)] + [filled[box]]))
    return image, int(mask.sum()), seconds


def _engine_version() -> str:
    """HEAD's short hash, and whether the add-on's files differ from it."""
    def git(*args: str) -> str:
        return subprocess.run(["git", *args], cwd=ROOT, capture_output=True, text=True, check=True).stdout.strip()

    edited = git("status", "--porcelain", "--", "addon")
    return git("rev-parse", "--short", "HEAD") + (" with uncommitted changes in addon/" if edited else "")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenes", default="hotel,lobby", help="comma separated, of hotel, lobby")
    parser.add_argument("--patchmatch", metavar="NPZ", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.patchmatch:
        patchmatch_step(args.patchmatch)
        return
    scenes = _scenes()
    table = Table(["scene", "object", "CLI s (wall)", "report s", "local s", "draft CLI s (wall)", "outline agreement",
                   "Align to Photo", "PatchMatch mask px", "PatchMatch s", "picture"],
                  title="Removal on real photographs (--align): photograph | ours, balanced | ours, draft | PatchMatch")
    notes = [f"The engine at commit {_engine_version()}."]
    for name in args.scenes.split(","):
        notes += crops(scenes[name], table)
    notes.append(f"PatchMatch (PyPatchMatch, patch radius 3, seed 0) fills the whole panorama tone-mapped to 8 bits "
                 f"(white: the crop's 97th percentile around the object, gamma 2.2) over the object's region as our "
                 f"run changed it (colour moved by more than {CHANGED:.0%}, dilated, the part joined to the object, "
                 f"holes filled); the crops show the same pixels.")
    write(table, notes=notes)


if __name__ == "__main__":
    main()
