"""Floor albedo from a real photograph (numpy only): the panorama projected onto the floor plane.

A photographed floor carries what a real one does: its grain, a rug, a desk foot, the dark
pixels where furniture meets it. Seen from the camera that took it, the floor at (x, y) shows
the photograph's pixel in the direction (x - ox, y - oy, -height); its radiance, scaled so that
the floor's median luminance is a plausible albedo and clipped below 1, is that point's albedo.
The photograph's lighting comes with it (a sunlit patch, the shade under a desk), as paint.

`baked_floor(room, photo)` writes the texture once under `.cache/photo_textures/` (named by a
hash of everything that decides it) and returns its path; Cycles maps it onto the floor.
`baked_walls` does the same for the four walls, projected from the same camera: a box room
then shows the photograph's walls where the photographed room's were not, stretched.
"""
from __future__ import annotations

import hashlib
import importlib.util
import json
from pathlib import Path

import numpy as np

from addon.geometry.latlong import direction_to_uv
from addon.io.exr import read_exr, write_exr

from .spec import WALLS, Photo, Room

REPO = Path(__file__).resolve().parents[1]
PHOTOS = REPO.parent / "shared" / "real_photos"
TEXTURES = REPO / ".cache" / "photo_textures"
_LUMA = np.array([0.2126, 0.7152, 0.0722])


def photo_path(source: str) -> Path:
    """The file of a photograph: one of the shared real photographs, or Blender's bundled
    `interior.exr` (found beside the installed bpy module). FileNotFoundError if absent."""
    if source == "interior.exr":
        spec = importlib.util.find_spec("bpy")
        found = sorted(Path(spec.origin).parent.glob("*/datafiles/studiolights/world/interior.exr")) if spec else []
        if not found:
            raise FileNotFoundError("Blender's interior.exr: no bpy module with its data files")
        return found[0]
    path = PHOTOS / source
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such photograph")
    return path


def texel_centres(room: Room, texel: float) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols) world x and y of the texture's texel centres over the room's floor: row 0
    at y = hi (the top of the image, which Cycles maps to v = 1), column 0 at x = lo."""
    return _grid((room.lo[0], room.hi[0]), (room.lo[1], room.hi[1]), texel)


def _grid(a: tuple[float, float], b: tuple[float, float], texel: float) -> tuple[np.ndarray, np.ndarray]:
    """(rows, cols) texel centres of a rectangle: a along the columns from a[0], b along the
    rows from b[1] at the top."""
    cols, rows = max(1, round((a[1] - a[0]) / texel)), max(1, round((b[1] - b[0]) / texel))
    x = a[0] + (np.arange(cols) + 0.5) * (a[1] - a[0]) / cols
    y = b[1] - (np.arange(rows) + 0.5) * (b[1] - b[0]) / rows
    return np.broadcast_to(x[None, :], (rows, cols)), np.broadcast_to(y[:, None], (rows, cols))


def wall_axis(wall: str) -> int:
    """The world axis a wall runs along (y for west and east, x for south and north)."""
    return 1 if wall in ("west", "east") else 0


def wall_points(room: Room, wall: str, texel: float) -> np.ndarray:
    """(rows, cols, 3) world points of the texel centres of a wall (one of `spec.WALLS`):
    columns along its axis from lo, row 0 at the ceiling."""
    axis = wall_axis(wall)
    a, z = _grid((room.lo[axis], room.hi[axis]), (room.lo[2], room.hi[2]), texel)
    fixed = {"west": room.lo[0], "east": room.hi[0], "south": room.lo[1], "north": room.hi[1]}[wall]
    points = np.empty((*a.shape, 3))
    points[..., axis], points[..., 1 - axis], points[..., 2] = a, fixed, z
    return points


def sample_bilinear(image: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """(..., 3) bilinear samples of a lat-long `image` (H, W, 3), row 0 at v = 1, at texture
    coordinates (u, v): wraps around the u seam, clamps at the poles."""
    h, w = image.shape[:2]
    x, y = np.asarray(u) * w - 0.5, (1.0 - np.asarray(v)) * h - 0.5
    x0, y0 = np.floor(x).astype(np.int64), np.floor(y).astype(np.int64)
    fx, fy = (x - x0)[..., None], (y - y0)[..., None]
    c0, c1 = np.mod(x0, w), np.mod(x0 + 1, w)
    r0, r1 = np.clip(y0, 0, h - 1), np.clip(y0 + 1, 0, h - 1)
    top = image[r0, c0] * (1 - fx) + image[r0, c1] * fx
    bottom = image[r1, c0] * (1 - fx) + image[r1, c1] * fx
    return top * (1 - fy) + bottom * fy


def projected_radiance(panorama: np.ndarray, photo: Photo, points: np.ndarray, floor: float) -> np.ndarray:
    """(..., 3) radiance the photograph shows towards world `points` (..., 3) from its camera,
    `height` above the `floor` (its z) at `origin`, turned by `yaw`."""
    d = np.asarray(points, dtype=np.float64) - np.array([*photo.origin, floor + photo.height])
    # The room's azimuth a shows the photograph's a - yaw.
    a = np.radians(-photo.yaw)
    turn = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    u, v = direction_to_uv(d, turn)
    return np.maximum(sample_bilinear(np.asarray(panorama, dtype=np.float64), u, v), 0.0)


def _albedo(radiance: np.ndarray, photo: Photo, median_of: np.ndarray) -> np.ndarray:
    scale = photo.median / max(float(np.median(median_of @ _LUMA)), 1e-12)
    return np.clip(radiance * scale, 0.0, photo.ceiling).astype(np.float32)


def floor_albedo(panorama: np.ndarray, room: Room, photo: Photo) -> np.ndarray:
    """(rows, cols, 3) float32 albedo of the floor (`texel_centres`), from `panorama`."""
    x, y = texel_centres(room, photo.texel)
    points = np.stack([x, y, np.full_like(x, room.lo[2])], axis=-1)
    radiance = projected_radiance(panorama, photo, points, room.lo[2])
    return _albedo(radiance, photo, radiance)


def wall_albedos(panorama: np.ndarray, room: Room, photo: Photo) -> dict[str, np.ndarray]:
    """Each wall's (rows, cols, 3) float32 albedo (`wall_points`), from `panorama`, scaled by
    one factor for the four: the median over them all is the photo's `median` (a wall the
    photograph shows darker stays darker)."""
    radiance = {w: projected_radiance(panorama, photo, wall_points(room, w, photo.texel), room.lo[2]) for w in WALLS}
    every = np.concatenate([r.reshape(-1, 3) for r in radiance.values()])
    return {w: _albedo(r, photo, every) for w, r in radiance.items()}


def texture_name(room: Room, photo: Photo, surface: str = "floor") -> str:
    """File name of a baked texture: the surface, and a hash of the photograph's bytes, the
    room's extent, the projection and this module's code."""
    h = hashlib.sha256(photo_path(photo.source).read_bytes())
    h.update(json.dumps([room.lo, room.hi, photo.__dict__], sort_keys=True).encode())
    h.update(Path(__file__).read_bytes())
    return f"{surface}-{h.hexdigest()[:20]}.exr"


def baked_floor(room: Room, photo: Photo, folder: Path = TEXTURES) -> Path:
    """The floor texture's EXR file (linear RGB albedo), baked unless already there."""
    path = folder / texture_name(room, photo)
    if not path.exists():
        folder.mkdir(parents=True, exist_ok=True)
        write_exr(str(path), floor_albedo(read_exr(str(photo_path(photo.source))), room, photo))
    return path


def baked_walls(room: Room, photo: Photo, folder: Path = TEXTURES) -> dict[str, Path]:
    """The walls' texture files by wall (`wall_albedos`), baked unless already there."""
    paths = {w: folder / texture_name(room, photo, f"wall-{w}") for w in WALLS}
    if not all(p.exists() for p in paths.values()):
        folder.mkdir(parents=True, exist_ok=True)
        for w, albedo in wall_albedos(read_exr(str(photo_path(photo.source))), room, photo).items():
            write_exr(str(paths[w]), albedo)
    return paths
