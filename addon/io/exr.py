"""Reading and writing the add-on's image files with OpenEXR and numpy only (no bpy).

Blender's own `Image.save()` colour-manages float images on the way out, so every EXR the
add-on writes goes through here instead: RGB float32, row 0 at the top, as on disk. PNG is
only needed for the 8-bit hidden-region mask, so a minimal zlib encoder does.
"""
from __future__ import annotations

import contextlib
import io
import os
import secrets
import struct
import sys
import tempfile
import zlib
from collections.abc import Callable, Iterator

import numpy as np
import OpenEXR

from ..errors import DimredError


def read_exr(path: str | os.PathLike[str]) -> np.ndarray:
    """(H, W, 3) float32 RGB of an EXR file, top row first (alpha and other channels ignored).

    Reads the first part that has R, G and B channels, scanline or tiled, half or float.
    """
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise DimredError(f"EXR file not found: {path}")
    if not OpenEXR.isOpenExrFile(path):
        raise DimredError(f"not an OpenEXR file: {path}")
    with _captured_library_messages() as messages:
        try:
            parts = OpenEXR.File(path, separate_channels=True).parts
        except (RuntimeError, ValueError) as exc:
            parts, failure = [], _library_reason(messages(), exc)
        else:
            # A file whose pixel data is cut short or corrupt opens with no parts.
            failure = _library_reason(messages(), "no readable image data")
    if not parts:
        raise DimredError(f"cannot read EXR file {path}: {failure}")
    found: list[str] = []
    for part in parts:
        channels = part.channels
        found.extend(channels)
        if all(name in channels for name in "RGB"):
            planes = [channels[name] for name in "RGB"]
            if any(c.xSampling != 1 or c.ySampling != 1 for c in planes):
                raise DimredError(f"EXR file {path} has subsampled colour channels, which are not supported")
            return np.stack([c.pixels for c in planes], axis=-1).astype(np.float32)
    listed = ", ".join(sorted(set(found))) or "none"
    raise DimredError(f"EXR file {path} has no R, G, B channels (channels: {listed})")


def write_exr(path: str | os.PathLike[str], image: np.ndarray) -> None:
    """Write (H, W, 3) RGB as a float32 ZIP-compressed scanline EXR, top row first, atomically."""
    rgb = np.asarray(image)
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"write_exr expects an (H, W, 3) array, got shape {rgb.shape}")
    rgb = rgb.astype(np.float32)
    channels = {name: np.ascontiguousarray(rgb[..., i]) for i, name in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}

    def write(temp_path: str) -> None:
        with _captured_library_messages() as messages:
            try:
                OpenEXR.File(header, channels).write(temp_path)
            except (RuntimeError, ValueError, OSError) as exc:
                raise DimredError(f"cannot write EXR file {path}: {_library_reason(messages(), exc)}") from None

    _write_atomically(os.fspath(path), write)


def write_png(path: str | os.PathLike[str], image8: np.ndarray) -> None:
    """Write a uint8 (H, W) grey or (H, W, 3) RGB array as an 8-bit PNG, atomically."""
    pixels = np.asarray(image8)
    if pixels.dtype != np.uint8 or pixels.ndim not in (2, 3) or (pixels.ndim == 3 and pixels.shape[2] != 3):
        raise ValueError(f"write_png expects uint8 (H, W) or (H, W, 3), got {pixels.dtype} {pixels.shape}")
    height, width = pixels.shape[:2]
    colour_type = 0 if pixels.ndim == 2 else 2
    rows = pixels.reshape(height, -1)
    # Filter type 0 (None) on every row: a zero byte in front of each scanline.
    raw = np.concatenate([np.zeros((height, 1), np.uint8), rows], axis=1).tobytes()

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    png = (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, colour_type, 0, 0, 0))
        + chunk(b"IDAT", zlib.compress(raw, 6))
        + chunk(b"IEND", b"")
    )

    def write(temp_path: str) -> None:
        with open(temp_path, "wb") as handle:
            handle.write(png)

    _write_atomically(os.fspath(path), write)


def _write_atomically(path: str, write: Callable[[str], None]) -> None:
    """Run `write` on a temporary file next to `path`, then rename it into place.

    The rename is atomic within one folder, so readers see the old file or the whole new one.
    """
    folder, name = os.path.split(os.path.abspath(path))
    temp_path = os.path.join(folder, f".{name}.{os.getpid()}.{secrets.token_hex(4)}.part")
    try:
        # Not mkstemp: its 0600 mode would survive the rename; this honours the umask.
        os.close(os.open(temp_path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
    except OSError as exc:
        raise DimredError(f"cannot write {path}: {exc.strerror or exc}") from None
    try:
        write(temp_path)
        os.replace(temp_path, path)
    except OSError as exc:
        _remove_quietly(temp_path)
        raise DimredError(f"cannot write {path}: {exc.strerror or exc}") from None
    except BaseException:
        _remove_quietly(temp_path)
        raise


def _remove_quietly(path: str) -> None:
    with contextlib.suppress(FileNotFoundError):
        os.unlink(path)


@contextlib.contextmanager
def _captured_library_messages() -> Iterator[Callable[[], str]]:
    """Capture what the OpenEXR library prints, so a bad file gives one error line, not three.

    The C core writes its diagnostics to file descriptor 2 and the binding warns through
    Python's sys.stdout; both are redirected for the duration and handed back as text.
    """
    captured_stdout = io.StringIO()
    with tempfile.TemporaryFile(mode="w+b") as sink:
        sys.stderr.flush()
        try:
            saved_fd = os.dup(2)
        except OSError:
            # File descriptor 2 is closed (no console): only Python's output needs catching.
            with contextlib.redirect_stdout(captured_stdout):
                yield captured_stdout.getvalue
            return
        os.dup2(sink.fileno(), 2)
        try:
            with contextlib.redirect_stdout(captured_stdout):
                yield lambda: _read_sink(sink) + captured_stdout.getvalue()
        finally:
            os.dup2(saved_fd, 2)
            os.close(saved_fd)


def _read_sink(sink: io.BufferedRandom) -> str:
    sink.flush()
    sink.seek(0)
    return sink.read().decode("utf-8", "replace")


def _library_reason(text: str, fallback: object) -> str:
    """The most specific line the library printed (its core error code first), or fallback."""
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    coded = [line for line in lines if "(EXR_ERR_" in line]
    if coded:
        # Core messages look like "<path>: (EXR_ERR_...) text"; our message names the path.
        _, sep, reason = coded[0].partition(": (")
        return f"({reason}" if sep else coded[0]
    if lines:
        return lines[-1].removeprefix("Warning: ")
    return str(fallback)
