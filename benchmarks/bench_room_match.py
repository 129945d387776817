"""Match Room measured: clicks to the room, Snap to Photo, Suggest Room and Object from Photo on
the Cycles rooms of known geometry (`scenes.rooms`, rendered once and cached), the click files
of the real photographs (tests/data/rooms/), and from a click file with objects to a removal that
runs (the command line, from an empty scene):
    .venv/bin/python benchmarks/bench_room_match.py
Prints four markdown tables and writes them into docs/results/bench_room_match.md
(`results.write`). The clicks on a render are its true corners projected to pixels and rounded,
as a user's clicks are; errors are per metre of the corner's distance from the probe (cm/m) or
relative (%); edge offsets are pixels at 1024x512.
"""
from __future__ import annotations

import dataclasses
import subprocess
import sys
import sysconfig
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from addon.geometry.latlong import pixel_directions
from addon.io.exr import read_exr
from addon.roommatch import clicks as click_file
from addon.roommatch.clicks import KnownLength, RoomClicks
from addon.roommatch.fit import fit_room
from addon.roommatch.object_box import box_from_click, silhouette
from addon.roommatch.object_shapes import object_proxy
from addon.roommatch.photo_edges import edge_offsets
from addon.roommatch.projection import project
from addon.roommatch.refine import refine_clicks
from addon.roommatch.suggest import suggest_room
from results import Table, write
from scenes.rooms import ROOMS, render_room
from tests.engine.roommatch.room_truth import clicks_of, distance_errors, floor_points, rotation_z

REPO = Path(__file__).resolve().parents[1]
PHOTOS = {"apartment": REPO.parent / "shared" / "real_photos" / "apartment.exr",
          "lobby": REPO.parent / "shared" / "real_photos" / "lobby.exr",
          "interior": next(Path(sysconfig.get_paths()["purelib"]).glob(
              "bpy/*/datafiles/studiolights/world/interior.exr"), Path("interior.exr"))}

# What the photographs' figures are, and what they are not (looked at on the pictures).
NOTES = (
    ("An edge's offset is the median distance from the strongest change of log-luminance within 6 px across "
     "its reprojection; furniture in front of a wall's foot is an edge too, so an edge counts as shown, not "
     "as clear. The edges clear on the photographs (tests/engine/roommatch/test_real_photos.py) lie within "
     "2 px; the others are named here."),
    ("apartment: edge 0, the window wall: the French door's bottom frame lies 2.5-3 px above the floor's edge "
     "and a dark band below it; the offsets split between the two, the clicks lie between them: the measure "
     "cannot tell which is the floor's, and a half pixel of the 512x256 photograph is 1 px here. The pillar "
     "shows two faces at its foot (edges 3 and 4, a corner clicked between them)."),
    ("lobby: corners where the walls' feet, traced column by column, cross; the far wall (edge 1) is clear, "
     "the green wall's foot (edge 3) is behind benches, the wall left of the far one (edge 0) is no one "
     "plane (a recessed corridor), the stairs' side (edge 2) is their lowest step's edge."),
    "interior (the hotel room): every floor edge is behind the bed, desk, armchair or curtains.",
    ("warehouse: no click file. Its floor meets the walls 10-30 m away, 2-7 degrees below the horizon, where "
     "one pixel of the 512x256 photograph moves a wall by 1.5-3 m; the walls traced column by column come "
     "out neither straight nor at right angles."),
    ("workshop: no click file. Benches, stands, partitions and machines stand along every wall: the "
     "photograph shows no floor corner and no stretch of a wall's foot."),
    ("The hotel armchair from one click: the arms' curves and the back's slope are no box's, stepped or not; "
     "the stepped box, grown to cover the outline and carved by the outline's cone from the probe, shows the "
     "outline (the carved proxy's agreement is its mesh traced). The outline stops at the seat's skirt (its "
     "dark legs are not in it): the removal's own segmentation takes the legs in beside the proxy's silhouette."),
)


def _worst(errors: np.ndarray) -> str:
    return f"{100 * errors.max():.2f}"


def _rooms() -> tuple[Table, Table]:
    rooms = Table(["room", "corners", "at true height, worst cm/m", "snapped, median / worst cm/m",
                   "door's height: camera %", "corners worst %", "wall's length: camera %", "corners worst %",
                   "floor edges px", "suggestion worst cm/m", "fit ms"],
                  title="Cycles rooms, 1024x512, clicks = true corners rounded to pixels")
    objects = Table(["room", "box from one click (m)", "turn deg", "agreement with outline", "with true box",
                     "seconds"], title="Object from Photo on the Cycles room with a box")
    for room in ROOMS.values():
        panorama = read_exr(render_room(room))
        corners, probe = np.asarray(room.corners), np.asarray(room.probe)
        rotation = rotation_z(room.world_rotation_z)
        floor = clicks_of(floor_points(corners), probe, room.width, room.height, rotation)

        def fit(clicks: RoomClicks, *, rotation=rotation, room=room):
            return fit_room(clicks, rotation=rotation, origin=room.probe[:2], ceiling_height=room.ceiling)

        clicks = RoomClicks(room.width, room.height, tuple(map(tuple, floor)), camera_height=room.probe[2])
        started = time.perf_counter()
        plain = fit(clicks)
        ms = 1000 * (time.perf_counter() - started)
        snapped = fit(refine_clicks(panorama, clicks, plain, rotation=rotation)[0])
        snap = distance_errors(snapped.corners, corners, probe)
        ends = clicks_of(room.door()[[0, 3]], probe, room.width, room.height, rotation)
        door = fit(dataclasses.replace(clicks, camera_height=None, known_length=KnownLength(
            "vertical", room.door_height, start=tuple(ends[0]), end=tuple(ends[1]))))
        wall = fit(dataclasses.replace(clicks, camera_height=None, manhattan=True, known_length=KnownLength(
            "wall", float(np.linalg.norm(corners[1] - corners[0])), edge=0)))
        edges = edge_offsets(panorama, plain, rotation=rotation).offsets[:len(corners)]
        found = suggest_room(panorama, width=room.width, height=room.height, rotation=rotation)
        if found.clicks is None:
            suggestion = "none"
        else:
            proposed = fit(dataclasses.replace(found.clicks, camera_height=room.probe[2])).corners
            nearest = np.array([proposed[np.argmin(np.linalg.norm(proposed - c, axis=1))] for c in corners])
            suggestion = f"{_worst(distance_errors(nearest, corners, probe))} ({len(proposed)} corners)"
        rooms.row(room.name, len(corners), _worst(distance_errors(plain.corners, corners, probe)),
                  f"{100 * np.median(snap):.2f} / {100 * snap.max():.2f}",
                  f"{100 * (door.camera_height / probe[2] - 1):+.2f}",
                  _worst(distance_errors(door.corners, corners, probe)),
                  f"{100 * (wall.camera_height / probe[2] - 1):+.2f}",
                  _worst(distance_errors(wall.corners, corners, probe)),
                  f"{np.nanmin(edges):.2f}-{np.nanmax(edges):.2f}", suggestion, f"{ms:.1f}")
        for x, y, width, depth, tall, turn in room.boxes:
            click = project(np.array([x, y, tall / 2]) - probe, room.width, room.height, rotation)
            started = time.perf_counter()
            box = box_from_click(panorama, tuple(np.round(click)), click_size=(room.width, room.height), probe=probe,
                                 rotation=rotation, inside=corners)
            seconds = time.perf_counter() - started
            rays = pixel_directions(room.width, room.height, rotation)
            fitted = np.array([*(box.bottom[:2] - probe[:2]), *np.log(box.size), box.turn])
            truth = np.array([x - probe[0], y - probe[1], np.log(width), np.log(depth), np.log(tall),
                              np.radians(turn)])
            seen, true = silhouette(fitted, rays, probe[2]), silhouette(truth, rays, probe[2])
            objects.row(room.name, " x ".join(f"{v:.2f}" for v in box.size) + f" (true {width} x {depth} x {tall})",
                        f"{np.degrees(box.turn):.1f} (true {turn})", f"{box.agreement:.3f}",
                        f"{np.count_nonzero(seen & true) / np.count_nonzero(seen | true):.3f}", f"{seconds:.2f}")
    return rooms, objects


def _photos() -> Table:
    table = Table(["photograph", "native size", "clicks", "floor edges px (edge: offset, shown >= 90 %)",
                   "ceiling edges px (shown >= 90 %)", "objects", "suggestion"],
                  title="Real photographs, edges at 1024x512 (a 512x256 photograph upsampled: a pixel of it is 2)")
    for name, path in PHOTOS.items():
        if not path.is_file():
            table.row(name, "-", "-", "photograph not on this machine", "", "", "")
            continue
        clicks = click_file.from_json(_click_file(name).read_text())
        panorama = read_exr(path)
        room = fit_room(clicks)
        found = edge_offsets(panorama, room)
        n = len(clicks.floor)

        def listed(offsets: np.ndarray, shown: np.ndarray) -> str:
            return ", ".join(f"{i}: {v:.1f}" for i, (v, s) in enumerate(zip(offsets, shown, strict=True))
                             if s >= 0.9 and np.isfinite(v))

        proxies = []
        for item in clicks.objects:
            proxy = object_proxy(panorama, item, click_size=(clicks.width, clicks.height), probe=room.probe,
                                 inside=room.corners)
            alone, base = proxy.details.get("box_agreement"), proxy.details.get("base")
            proxies.append(f"{item.name}: {proxy.kind} " + " x ".join(f"{v:.2f}" for v in proxy.size)
                           + f" m, agreement {proxy.agreement:.3f}"
                           + ("" if base is None else f" ({base['shape']} {base['agreement']:.3f}, "
                              f"{proxy.details['triangles']} triangles)")
                           + ("" if alone is None else f" (the box alone {alone:.3f})"))
        suggestion = suggest_room(panorama, width=panorama.shape[1], height=panorama.shape[0])
        table.row(name, f"{panorama.shape[1]}x{panorama.shape[0]}", f"{clicks.click_count()} + height",
                  listed(found.offsets[:n], found.shown[:n]) or "none",
                  (listed(found.offsets[n:2 * n], found.shown[n:2 * n]) or "none") if clicks.ceiling is not None
                  else "no ceiling click",
                  "; ".join(proxies) or "-",
                  "none" if suggestion.clicks is None else f"{len(suggestion.clicks.floor)} corners")
    return table


def _end_to_end() -> Table:
    """From the click file and an empty scene to a removal that runs, through the command line as
    a user runs it: `dimred room` (the room and the click file's objects), then `dimred remove`."""
    table = Table(["photograph", "clicks", "room + proxies s", "removal s (draft)", "removal ran"],
                  title="From an empty scene to a removal: dimred room --clicks, then dimred remove --quality draft")
    for name, path in PHOTOS.items():
        clicks_path = _click_file(name)
        clicks = click_file.from_json(clicks_path.read_text())
        if not path.is_file() or not clicks.objects:
            continue
        with tempfile.TemporaryDirectory() as folder:
            work = Path(folder)
            started = time.perf_counter()
            _cli("room", "--clicks", str(clicks_path), "--panorama", str(path), "--save", str(work / "room.blend"),
                 "--out", str(work / "room"))
            room_seconds = time.perf_counter() - started
            started = time.perf_counter()
            names = [arg for item in clicks.objects for arg in ("--object", item.name)]
            _cli("remove", str(work / "room.blend"), *names, "--quality", "draft", "--out", str(work / "removed"))
            removal_seconds = time.perf_counter() - started
            ran = (work / "removed" / "edited.exr").is_file()
        table.row(name, f"{clicks.click_count()} + height ({len(clicks.floor)} floor, "
                  f"{int(clicks.ceiling is not None)} ceiling, {sum(len(o.points()) for o in clicks.objects)} object)",
                  f"{room_seconds:.1f}", f"{removal_seconds:.1f}", "yes, edited.exr written" if ran else "no")
    return table


def _cli(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "addon.cli", *args], cwd=REPO, check=True, capture_output=True)


def _click_file(name: str) -> Path:
    return REPO / "tests" / "data" / "rooms" / f"{name}.json"


def main() -> None:
    rooms, objects = _rooms()
    write(rooms, objects, _photos(), _end_to_end(), notes=NOTES)


if __name__ == "__main__":
    main()
