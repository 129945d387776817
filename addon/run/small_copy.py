"""Small copies of panoramas for the previews: their size, resampling to it, and a cache of
the small copy of each EXR file (no bpy).

Previews are shown at most `PREVIEW_WIDTH` pixels wide whatever the panorama's size: pushing a
full-size image into Blender on the main thread would freeze the interface for seconds at 16K.
Reading a large EXR takes seconds too, so the small copy of a file is kept on disk, keyed by
the file's path, modification time and size, where the next run finds it in milliseconds.
"""
from __future__ import annotations

import contextlib
import hashlib
import os
import secrets
import tempfile
from dataclasses import dataclass

import numpy as np

from ..geometry.resample import resample_axis
from ..io.exr import read_exr

PREVIEW_WIDTH = 1024
# Copies kept in a cache folder (the newest); one is 6 MB at the preview size.
KEEP = 32


def preview_shape(height: int, width: int, *, limit: int = PREVIEW_WIDTH) -> tuple[int, int]:
    """(height, width) of the preview of a `height` x `width` panorama: at most `limit` wide,
    never larger than the panorama, the aspect kept."""
    if width <= limit:
        return height, width
    return max(1, round(height * limit / width)), limit


def resample(image: np.ndarray, height: int, width: int) -> np.ndarray:
    """(height, width, C) float32 lat-long `image` resampled (`geometry.resample`)."""
    out = np.asarray(image, dtype=np.float32)
    for axis, size in ((0, height), (1, width)):
        out = resample_axis(out, size, axis=axis)
    return out


@dataclass(frozen=True)
class SmallCopy:
    image: np.ndarray  # (h, w, 3) float32 at `preview_shape` of the full size
    full_shape: tuple[int, int]  # (height, width) of the panorama it was made from


def of_image(image: np.ndarray) -> SmallCopy:
    height, width = image.shape[:2]
    return SmallCopy(resample(image, *preview_shape(height, width)), (height, width))


def default_folder() -> str:
    return os.path.join(tempfile.gettempdir(), "dimred-small-copies")


def _cache_file(path: str, stat: os.stat_result, folder: str) -> str:
    identity = f"{os.path.normcase(os.path.abspath(path))}\0{stat.st_mtime_ns}\0{stat.st_size}"
    return os.path.join(folder, hashlib.sha1(identity.encode()).hexdigest() + ".npz")


def cached(path: str, folder: str) -> SmallCopy | None:
    """The stored small copy of the file at `path` as it is now, if there is one."""
    try:
        with np.load(_cache_file(path, os.stat(path), folder)) as data:
            return SmallCopy(data["image"], tuple(int(n) for n in data["full_shape"]))
    except (OSError, ValueError, KeyError):
        return None


def store(path: str, copy: SmallCopy, folder: str, *, stat: os.stat_result | None = None) -> None:
    """Keep `copy` as the small copy of the file at `path` (whose `stat` it is, by default the
    file's own: a file written under a temporary name keeps its stat when renamed). A cache that
    cannot be written is no error: the next run reads the file again."""
    with contextlib.suppress(OSError):
        os.makedirs(folder, exist_ok=True)
        final = _cache_file(path, stat or os.stat(path), folder)
        temporary = f"{final}.{secrets.token_hex(4)}.tmp.npz"
        try:
            np.savez(temporary, image=copy.image, full_shape=np.array(copy.full_shape))
            os.replace(temporary, final)
        finally:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(temporary)
        _prune(folder, final)


def of_file(path: str, folder: str) -> SmallCopy:
    """The small copy of the EXR file at `path`: the stored one, else made from the file."""
    copy = cached(path, folder)
    if copy is None:
        stat = os.stat(path)
        copy = of_image(read_exr(path))
        store(path, copy, folder, stat=stat)
    return copy


def _prune(folder: str, newest: str) -> None:
    """Keep the `KEEP` newest copies, `newest` among them."""
    entries = [e for e in os.scandir(folder) if e.name.endswith(".npz") and ".tmp." not in e.name]
    entries.sort(key=lambda e: (e.path == newest, e.stat().st_mtime_ns), reverse=True)
    for entry in entries[KEEP:]:
        with contextlib.suppress(OSError):
            os.unlink(entry.path)
