"""Reading and writing the add-on's image files with OpenEXR and numpy only (no bpy).

Blender's own `Image.save()` colour-manages float images on the way out, so every EXR the
add-on writes goes through here instead: RGB float32, row 0 at the top, as on disk. PNG is
only needed for the 8-bit hidden-region mask, so a minimal zlib encoder does.

Panoramas run to 16384 x 8192 (1.6 GB as float32 RGB), so pixels travel in bands of rows:
a read fills one preallocated float32 array, a write takes its rows from a callable, and
neither holds more than a band besides the image. Banded access exists only in the binding's
scanline interface (`InputFile`, `OutputFile`), which sees the first part of a file; the
`File` interface reads every part whole and is used for a colour part further in.
"""
from __future__ import annotations

import contextlib
import io
import os
import secrets
import struct
import sys
import tempfile
import threading
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import TypeVar

import Imath
import numpy as np
import OpenEXR

from ..errors import DimredError

#: The most rows per band. The library holds Python's interpreter lock while it encodes or
#: decodes a band, which stalls Blender's interface when the worker thread reads or writes, so
#: a band holds about _BAND_PIXELS pixels per library thread (0.03 s); its rows are a multiple
#: of the lines one chunk holds (32 for PIZ, which is written, and for B44 and DWAA; 16 for ZIP),
#: so that no chunk is decoded twice except under DWAB's 256.
BAND_ROWS = 256
_BAND_PIXELS = 1 << 18
#: The library's own threads, which encode or decode the chunks of one band side by side (it
#: starts none of its own: an 8192 x 4096 difference took 3.8 s to write on one core, 2.2 s
#: on two). A band then holds a chunk per thread, and the interpreter lock is held as long.
_MAX_CODEC_THREADS = 8

_FLOAT = Imath.PixelType(Imath.PixelType.FLOAT)
# Lossless, and for noisy float data (a difference image, a photograph) twice as fast to write
# as ZIP and smaller: 4.5 s against 8.2 s for an 8192 x 4096 edited panorama here.
_PIZ = Imath.Compression(Imath.Compression.PIZ_COMPRESSION)
# What the library's failures arrive as: the scanline interface raises OSError, the File
# interface RuntimeError or ValueError.
_SCANLINE_ERRORS = (OSError,)
_FILE_ERRORS = (RuntimeError, ValueError, OSError)

_T = TypeVar("_T")


@dataclass(frozen=True)
class _ColourPart:
    """The part of an EXR file that holds R, G and B: its index and data window."""

    index: int
    width: int
    height: int
    top: int  # the data window's first scanline number


def exr_size(path: str | os.PathLike[str]) -> tuple[int, int]:
    """(width, height) of the image `read_exr` reads from the file, from the headers alone."""
    part = _colour_part(os.fspath(path))
    return part.width, part.height


def read_exr(path: str | os.PathLike[str]) -> np.ndarray:
    """(H, W, 3) float32 RGB of an EXR file, top row first (alpha and other channels ignored).

    Reads the first part that has R, G and B channels, scanline or tiled, half or float, into
    one preallocated array: a band of rows at a time when it is the file's first part (besides
    the image, one band is held), whole when it is a later one (every part's pixels are held).
    """
    path = os.fspath(path)
    part = _colour_part(path)
    rgb = np.empty((part.height, part.width, 3), np.float32)
    if part.index == 0:
        _library_call(path, "read", lambda: _read_bands(path, part, rgb), _SCANLINE_ERRORS)
    else:
        _library_call(path, "read", lambda: _read_whole(path, part, rgb), _FILE_ERRORS)
    return rgb


def write_exr(path: str | os.PathLike[str], image: np.ndarray) -> None:
    """Write (H, W, 3) RGB as a float32 PIZ-compressed scanline EXR, top row first, atomically.

    A float32 image is written as it is, by the library's whole-image interface, which lets
    go of Python's interpreter lock while it compresses (Blender's interface stays responsive
    while a worker writes); any other dtype is converted a band at a time (`write_exr_rows`),
    so no full-size copy is made.
    """
    rgb = np.asarray(image)
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"write_exr expects an (H, W, 3) array, got shape {rgb.shape}")
    if rgb.dtype != np.float32 or not rgb.flags.c_contiguous:
        write_exr_rows(path, rgb.shape[0], rgb.shape[1], lambda start, stop: rgb[start:stop])
        return
    header = {"compression": OpenEXR.PIZ_COMPRESSION, "type": OpenEXR.scanlineimage}

    def write(temp_path: str) -> None:
        _library_call(path, "write", lambda: OpenEXR.File(header, {"RGB": rgb}).write(temp_path), _FILE_ERRORS)
        _library_call(path, "write", lambda: _check_complete(path, temp_path, rgb.shape[0]), _SCANLINE_ERRORS)

    _write_atomically(os.fspath(path), write)


def write_exr_rows(path: str | os.PathLike[str], height: int, width: int,
                   rows: Callable[[int, int], np.ndarray]) -> None:
    """Write a `height` x `width` image as `write_exr` does, taking its pixels from
    `rows(start, stop)`: the (stop - start, width, 3) band of rows start:stop.

    Bands are asked for once each, top first, and only one is held at a time, so the whole
    image need never exist (`RemovalResult.edited_rows`). An exception from `rows` ends the
    write and leaves no file behind.
    """
    if height < 1 or width < 1:
        raise ValueError(f"write_exr_rows expects a positive size, got {width}x{height}")
    header = OpenEXR.Header(int(width), int(height))  # R, G, B float32, rows top first
    header["compression"] = _PIZ

    def write(temp_path: str) -> None:
        _library_call(path, "write", lambda: _write_bands(temp_path, header, height, width, rows), _SCANLINE_ERRORS)
        _library_call(path, "write", lambda: _check_complete(path, temp_path, height), _SCANLINE_ERRORS)

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


def _colour_part(path: str) -> _ColourPart:
    """Which part `read_exr` reads and its size, from the file's headers."""
    if not os.path.isfile(path):
        raise DimredError(f"EXR file not found: {path}")
    if not OpenEXR.isOpenExrFile(path):
        raise DimredError(f"not an OpenEXR file: {path}")
    found: list[str] = []
    for index, header in enumerate(_library_call(path, "read", lambda: _headers(path), _FILE_ERRORS)):
        channels = {channel.name: channel for channel in header["channels"]}
        found.extend(channels)
        if all(name in channels for name in "RGB"):
            if any(channels[name].xSampling != 1 or channels[name].ySampling != 1 for name in "RGB"):
                raise DimredError(f"EXR file {path} has subsampled colour channels, which are not supported")
            (left, top), (right, bottom) = header["dataWindow"]
            return _ColourPart(index, int(right - left + 1), int(bottom - top + 1), int(top))
    listed = ", ".join(sorted(set(found))) or "none"
    raise DimredError(f"EXR file {path} has no R, G, B channels (channels: {listed})")


def _headers(path: str) -> list[dict]:
    parts = OpenEXR.File(path, header_only=True).parts
    if not parts:
        raise RuntimeError("no readable image data")
    return [part.header for part in parts]


def _read_bands(path: str, part: _ColourPart, rgb: np.ndarray) -> None:
    """Fill `rgb` from the file's first part, converted to float32 by the library, band by band."""
    source = OpenEXR.InputFile(path)
    try:
        for start, stop in _bands(part.height, part.width, chunk=32):
            _read_band(source, part, rgb[start:stop], part.top + start)
    finally:
        source.close()


def _read_band(source: OpenEXR.InputFile, part: _ColourPart, band: np.ndarray, first: int) -> None:
    # A function of its own so that a band's planes are freed before the next band's are read.
    planes = source.channels(["R", "G", "B"], _FLOAT, first, first + len(band) - 1)
    for i, plane in enumerate(planes):
        band[..., i] = np.frombuffer(plane, np.float32).reshape(len(band), part.width)


def _read_whole(path: str, part: _ColourPart, rgb: np.ndarray) -> None:
    """Fill `rgb` from a later part, which only the File interface reaches (it reads all parts)."""
    parts = OpenEXR.File(path, separate_channels=True).parts
    if len(parts) <= part.index:
        # A file whose pixel data is cut short or corrupt opens with no parts.
        raise RuntimeError("no readable image data")
    channels = parts[part.index].channels
    for i, name in enumerate("RGB"):
        rgb[..., i] = channels[name].pixels


def _write_bands(path: str, header: dict, height: int, width: int, rows: Callable[[int, int], np.ndarray]) -> None:
    target = OpenEXR.OutputFile(path, header)
    try:
        for start, stop in _bands(height, width, chunk=32):
            target.writePixels(_planes(rows, start, stop, width), stop - start)
    finally:
        target.close()


def _planes(rows: Callable[[int, int], np.ndarray], start: int, stop: int, width: int) -> dict[str, np.ndarray]:
    """The R, G and B planes of rows(start, stop), contiguous float32 as the library takes them."""
    band = np.asarray(rows(start, stop))
    if band.shape != (stop - start, width, 3):
        raise ValueError(f"rows({start}, {stop}) gave an array of shape {band.shape}, not {(stop - start, width, 3)}")
    return {name: np.ascontiguousarray(band[..., i], dtype=np.float32) for i, name in enumerate("RGB")}


def _check_complete(path: str, temp_path: str, height: int) -> None:
    """DimredError unless the written file's bottom row reads back.

    The library writes the chunk offsets and the last buffered bytes as it closes the file, and
    drops any failure there (a disk that fills up at the end). The bottom rows are the last
    chunk written, so a file cut short fails to give them.
    """
    written = OpenEXR.InputFile(temp_path)
    try:
        written.channels(["R"], _FLOAT, height - 1, height - 1)
    except OSError:
        raise DimredError(f"cannot write EXR file {path}: the file on disk is incomplete (is the disk full?)") from None
    finally:
        written.close()


def _codec_threads() -> int:
    """The library's worker threads, started at the first read or write where nothing in the
    process has set them (a setting of the library's, kept for the process's life)."""
    if OpenEXR.global_thread_count() == 0:
        OpenEXR.set_global_thread_count(min(os.cpu_count() or 1, _MAX_CODEC_THREADS))
    return max(1, OpenEXR.global_thread_count())


def _bands(height: int, width: int, *, chunk: int) -> Iterator[tuple[int, int]]:
    per_thread = max(chunk, _BAND_PIXELS // max(width, 1) // chunk * chunk)
    rows = min(BAND_ROWS, per_thread * _codec_threads())
    for start in range(0, height, rows):
        yield start, min(start + rows, height)


def _library_call(path: str, verb: str, call: Callable[[], _T], errors: tuple[type[Exception], ...]) -> _T:
    """call(), its failures of type `errors` turned into one DimredError line naming `path`."""
    _codec_threads()
    with _captured_library_messages() as messages:
        try:
            return call()
        except errors as exc:
            reason = _library_reason(messages(), exc)
    raise DimredError(f"cannot {verb} EXR file {path}: {reason}")



class _Capture:
    """What the OpenEXR library prints, captured so that a bad file gives one error line, not
    three. The C core writes its diagnostics to file descriptor 2 and the binding warns through
    Python's sys.stdout; both are redirected while any thread is inside a library call, and
    handed back as text.

    Both are the process's own, so there is one redirection for all threads, counted: the
    command line writes the difference on a second thread beside the edited panorama, and two
    redirections of their own restored in the wrong order left sys.stdout captured and the
    command's last line unprinted.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._inside = 0
        self._text = io.StringIO()
        self._sink: io.BufferedRandom | None = None
        self._saved_fd: int | None = None
        self._saved_stdout: object = None

    @contextlib.contextmanager
    def messages(self) -> Iterator[Callable[[], str]]:
        with self._lock:
            if not self._inside:
                self._redirect()
            self._inside += 1
            sink, text = self._sink, self._text

        def printed() -> str:
            with self._lock:
                return (_read_sink(sink) if sink is not None and not sink.closed else "") + text.getvalue()

        try:
            yield printed
        finally:
            with self._lock:
                self._inside -= 1
                if not self._inside:
                    self._restore()

    def _redirect(self) -> None:
        sys.stderr.flush()
        self._text, self._saved_stdout = io.StringIO(), sys.stdout
        sys.stdout = self._text
        try:
            self._saved_fd = os.dup(2)
        except OSError:
            # File descriptor 2 is closed (no console): only Python's output needs catching.
            self._saved_fd = None
            return
        self._sink = tempfile.TemporaryFile(mode="w+b")
        os.dup2(self._sink.fileno(), 2)

    def _restore(self) -> None:
        sys.stdout = self._saved_stdout
        if self._saved_fd is not None:
            os.dup2(self._saved_fd, 2)
            os.close(self._saved_fd)
            self._saved_fd = None
        if self._sink is not None:
            self._sink.close()
            self._sink = None


_CAPTURE = _Capture()
_captured_library_messages = _CAPTURE.messages


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
