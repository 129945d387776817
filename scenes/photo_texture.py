"""Floor albedo from a real photograph (numpy only): the panorama projected onto the floor plane.

A photographed floor carries what a real one does: its grain, a rug, a desk foot, the dark
pixels where furniture meets it. Seen from the camera that took it, the floor at (x, y) shows
the photograph's pixel in the direction (x - ox, y - oy, -height); its radiance, scaled so that
the floor's median luminance is a plausible albedo and clipped below 1, is that point's albedo.
The photograph's lighting comes with it (a sunlit patch, the shade under a desk), as paint.

`baked_floor(room, photo)` writes the texture once under `.cache/photo_textures/` (named by a
hash of everything that decides it) and returns its path; Cycles maps it onto the floor.
"""
from __future__ import annotations

import hashlib
import importlib.util
import json
from pathlib import Path

import numpy as np

from addon.geometry.latlong import direction_to_uv
from addon.io.exr import read_exr, write_exr

from .spec import Photo, Room

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
    (x0, y0, _), (x1, y1, _) = room.lo, room.hi
    cols, rows = max(1, round((x1 - x0) / texel)), max(1, round((y1 - y0) / texel))
    x = x0 + (np.arange(cols) + 0.5) * (x1 - x0) / cols
    y = y1 - (np.arange(rows) + 0.5) * (y1 - y0) / rows
    return np.broadcast_to(x[None, :], (rows, cols)), np.broadcast_to(y[:, None], (rows, cols))


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


def floor_albedo(panorama: np.ndarray, room: Room, photo: Photo) -> np.ndarray:
    """(rows, cols, 3) float32 albedo of the floor (`texel_centres`), from `panorama`."""
    x, y = texel_centres(room, photo.texel)
    d = np.stack([x - photo.origin[0], y - photo.origin[1], np.full_like(x, -photo.height)], axis=-1)
    # The room's azimuth a shows the photograph's a - yaw.
    a = np.radians(-photo.yaw)
    turn = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    u, v = direction_to_uv(d, turn)
    radiance = np.maximum(sample_bilinear(np.asarray(panorama, dtype=np.float64), u, v), 0.0)
    scale = photo.median / max(float(np.median(radiance @ _LUMA)), 1e-12)
    return np.clip(radiance * scale, 0.0, photo.ceiling).astype(np.float32)


def texture_name(room: Room, photo: Photo) -> str:
    """File name of the baked texture: a hash of the photograph's bytes, the floor's extent, the
    projection and this module's code."""
    h = hashlib.sha256(photo_path(photo.source).read_bytes())
    h.update(json.dumps([room.lo, room.hi, photo.__dict__], sort_keys=True).encode())
    h.update(Path(__file__).read_bytes())
    return f"floor-{h.hexdigest()[:20]}.exr"


def baked_floor(room: Room, photo: Photo, folder: Path = TEXTURES) -> Path:
    """The floor texture's EXR file (linear RGB albedo), baked unless already there."""
    path = folder / texture_name(room, photo)
    if not path.exists():
        folder.mkdir(parents=True, exist_ok=True)
        write_exr(str(path), floor_albedo(read_exr(str(photo_path(photo.source))), room, photo))
    return path
