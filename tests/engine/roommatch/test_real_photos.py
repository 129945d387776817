"""Match Room on real photographs: click files made by looking at the panoramas (tests/data/rooms/,
clicks placed on zoomed crops), their rooms' reprojected floor and ceiling edges measured against
the photograph's edges at 1024 x 512 (issue 35: within 2 px).

Only edges the photograph shows unoccluded along their whole length are held to the bound (a bed,
a desk or an armchair in front of a wall's foot hides it). Known misses, measured and left out:
the apartment's window wall (the French door's bottom frame 2.5-3 px above the floor's edge and
a dark band below it, the offsets split between the two: 2.9 px); the hotel room's (interior.exr)
floor edges, all behind its bed, desk, armchair and curtains (the curtains' wavy hem scatters
2.3 px about the window wall's). The apartment's pillar shows two faces at its foot (a corner at
(76, 170) between them, 1.3 px; one face through both was 4.2 px off). The lobby's corners are
where its walls' feet, traced column by column on the photograph (a recessed corridor, benches,
the reception desk and the stairs left out), cross: its far wall's foot is clear (0.8 px); its
green wall's foot is behind benches, the wall left of the far one is no one plane (3.6-4.1 px),
and the stairs' side is the lowest step's edge.

The hotel room's armchair from its one click (the click file's object) agrees with its
segmented outline at 0.95 or more (issue 35): no box nor stepped box does (0.84, 0.91: curved
arms, a sloping back), its carved proxy does.
"""
from __future__ import annotations

import sysconfig
from pathlib import Path

import numpy as np
import pytest

from addon.io.exr import read_exr
from addon.roommatch import clicks as click_file
from addon.roommatch.fit import fit_room
from addon.roommatch.object_shapes import object_proxy
from addon.roommatch.photo_edges import edge_offsets

DATA = Path(__file__).resolve().parents[2] / "data" / "rooms"
PHOTOS = Path(__file__).resolve().parents[4] / "shared" / "real_photos"
# The edges (`photo_edges.EdgeOffsets.kinds`) each photograph shows unoccluded.
CLEAR = {
    "apartment": ("floor 1", "floor 2", "floor 3", "floor 5", "floor 6", "floor 7", "ceiling 0", "ceiling 1",
                  "ceiling 5", "corner 2", "corner 5"),
    "interior": ("ceiling 3",),
    "lobby": ("floor 1",),
}


def _photo(name: str) -> Path:
    if name == "interior":
        found = sorted(Path(sysconfig.get_paths()["purelib"]).glob("bpy/*/datafiles/studiolights/world/interior.exr"))
        path = found[0] if found else Path("interior.exr")
    else:
        path = PHOTOS / f"{name}.exr"
    if not path.is_file():
        pytest.skip(f"{path}: the photograph is not on this machine")
    return path


@pytest.mark.parametrize("name", sorted(CLEAR))
def test_clear_edges_lie_within_two_pixels(name: str) -> None:
    clicks = click_file.from_json((DATA / f"{name}.json").read_text())
    room = fit_room(clicks)
    found = edge_offsets(read_exr(_photo(name)), room)
    offsets = dict(zip(found.kinds(), found.offsets, strict=True))
    far = {kind: round(float(offsets[kind]), 2) for kind in CLEAR[name] if not offsets[kind] <= 2.0}
    assert not far, f"edges farther than 2 px from the photograph's: {far}"
    assert np.all(room.corner_errors < 0.5)


def test_the_hotel_armchair_from_one_click_agrees_with_its_outline() -> None:
    clicks = click_file.from_json((DATA / "interior.json").read_text())
    room = fit_room(clicks)
    proxy = object_proxy(read_exr(_photo("interior")), clicks.objects[0], click_size=(clicks.width, clicks.height),
                         probe=room.probe, inside=room.corners)
    assert proxy.kind == "carved stepped box"
    assert proxy.agreement >= 0.95
