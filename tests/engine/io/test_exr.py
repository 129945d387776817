"""EXR and PNG files: what the add-on writes reads back exactly, other EXR layouts read right,
bad files give one clear error line, and a failed write leaves the old file alone."""
from __future__ import annotations

import os
import struct
import tracemalloc
import zlib

import numpy as np
import OpenEXR
import pytest

from addon.errors import DimredError
from addon.io import exr


def _hdr_image(height: int = 6, width: int = 10) -> np.ndarray:
    rng = np.random.default_rng(3)
    return (rng.random((height, width, 3)) * np.array([1.0, 100.0, 20000.0]) - 0.25).astype(np.float32)


def _write_raw(path, channels: dict, **header) -> None:
    """Write an EXR with OpenEXR directly, in layouts the add-on itself never writes."""
    base = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    OpenEXR.File({**base, **header}, channels).write(str(path))


def test_round_trip_is_exact_float32_top_row_first(tmp_path):
    image = _hdr_image()
    image[0, 0] = [1.0, 2.0, 3.0]
    path = tmp_path / "a.exr"
    exr.write_exr(path, image)
    back = exr.read_exr(path)
    assert back.dtype == np.float32 and back.shape == image.shape
    np.testing.assert_array_equal(back, image)
    with OpenEXR.File(str(path), separate_channels=True) as written:
        channels = written.channels()
        assert sorted(channels) == ["B", "G", "R"]
        assert all(c.pixels.dtype == np.float32 for c in channels.values())
        # Row 0 on disk is the top row: no flip anywhere.
        assert channels["R"].pixels[0, 0] == 1.0 and channels["B"].pixels[0, 0] == 3.0


def test_write_accepts_float64_and_rejects_other_shapes(tmp_path):
    image = _hdr_image().astype(np.float64)
    exr.write_exr(tmp_path / "d.exr", image)
    np.testing.assert_array_equal(exr.read_exr(tmp_path / "d.exr"), image.astype(np.float32))
    with pytest.raises(ValueError):
        exr.write_exr(tmp_path / "x.exr", np.zeros((4, 4, 4), np.float32))


def test_reads_rgba_half_tiled(tmp_path):
    image = _hdr_image().astype(np.float16)
    tiles = OpenEXR.TileDescription()
    tiles.xSize, tiles.ySize, tiles.mode = 4, 4, OpenEXR.ONE_LEVEL
    channels = {c: np.ascontiguousarray(image[..., i]) for i, c in enumerate("RGB")}
    channels["A"] = np.full(image.shape[:2], 0.5, np.float16)
    _write_raw(tmp_path / "h.exr", channels, type=OpenEXR.tiledimage, tiles=tiles, compression=OpenEXR.PIZ_COMPRESSION)
    back = exr.read_exr(tmp_path / "h.exr")
    assert back.dtype == np.float32 and back.shape == image.shape
    np.testing.assert_array_equal(back, image.astype(np.float32))


def test_reads_decreasing_line_order_top_row_first(tmp_path):
    image = _hdr_image()
    _write_raw(
        tmp_path / "dec.exr",
        {c: np.ascontiguousarray(image[..., i]) for i, c in enumerate("RGB")},
        lineOrder=OpenEXR.DECREASING_Y,
    )
    np.testing.assert_array_equal(exr.read_exr(tmp_path / "dec.exr"), image)


def test_reads_the_part_with_colour_channels(tmp_path):
    image = _hdr_image()
    depth = OpenEXR.Part({"type": OpenEXR.scanlineimage}, {"Z": np.ones(image.shape[:2], np.float32)})
    channels = {c: np.ascontiguousarray(image[..., i]) for i, c in enumerate("RGB")}
    colour = OpenEXR.Part({"type": OpenEXR.scanlineimage}, channels)
    OpenEXR.File([depth, colour]).write(str(tmp_path / "parts.exr"))
    np.testing.assert_array_equal(exr.read_exr(tmp_path / "parts.exr"), image)


@pytest.fixture
def small_bands(monkeypatch):
    """Bands of 4 rows, so that images of a few rows take several."""
    monkeypatch.setattr(exr, "BAND_ROWS", 4)


@pytest.mark.usefixtures("small_bands")
def test_reads_band_by_band_from_a_data_window_off_the_origin(tmp_path):
    image = _hdr_image(height=11)
    window = (np.array([2, 3], np.int32), np.array([11, 13], np.int32))
    _write_raw(tmp_path / "w.exr", {c: np.ascontiguousarray(image[..., i]) for i, c in enumerate("RGB")},
               dataWindow=window, displayWindow=window)
    np.testing.assert_array_equal(exr.read_exr(tmp_path / "w.exr"), image)
    assert exr.exr_size(tmp_path / "w.exr") == (10, 11)


@pytest.mark.usefixtures("small_bands")
def test_half_float_is_read_band_by_band(tmp_path):
    image = _hdr_image(height=9).astype(np.float16)
    _write_raw(tmp_path / "h.exr", {c: np.ascontiguousarray(image[..., i]) for i, c in enumerate("RGB")},
               lineOrder=OpenEXR.DECREASING_Y)
    np.testing.assert_array_equal(exr.read_exr(tmp_path / "h.exr"), image.astype(np.float32))


def test_size_comes_from_the_header_alone(tmp_path):
    exr.write_exr(tmp_path / "full.exr", _hdr_image(height=40, width=80))
    data = (tmp_path / "full.exr").read_bytes()
    # With its pixel data cut short the file cannot be read, but its header still gives the size.
    (tmp_path / "cut.exr").write_bytes(data[: len(data) // 2])
    assert exr.exr_size(tmp_path / "cut.exr") == (80, 40)
    with pytest.raises(DimredError, match="cannot read EXR file"):
        exr.read_exr(tmp_path / "cut.exr")


def test_size_of_the_part_with_colour_channels(tmp_path):
    # Parts share the display window; the depth part's data covers a corner of it.
    display = (np.array([0, 0], np.int32), np.array([9, 5], np.int32))
    corner = (np.array([0, 0], np.int32), np.array([4, 2], np.int32))
    depth = OpenEXR.Part({"type": OpenEXR.scanlineimage, "displayWindow": display, "dataWindow": corner},
                         {"Z": np.ones((3, 5), np.float32)})
    colour = OpenEXR.Part({"type": OpenEXR.scanlineimage, "displayWindow": display},
                          {c: np.ascontiguousarray(_hdr_image()[..., i]) for i, c in enumerate("RGB")})
    OpenEXR.File([depth, colour]).write(str(tmp_path / "parts.exr"))
    assert exr.exr_size(tmp_path / "parts.exr") == (10, 6)
    with pytest.raises(DimredError, match="not found"):
        exr.exr_size(tmp_path / "nope.exr")


def _peak_bytes(call) -> int:
    """The most memory Python and numpy held at once during call(), above what they held before."""
    tracemalloc.start()
    try:
        call()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


@pytest.mark.usefixtures("small_bands")
def test_read_and_write_hold_one_band_besides_the_image(tmp_path):
    image = _hdr_image(height=128, width=256)
    band = image[: exr.BAND_ROWS].nbytes
    assert _peak_bytes(lambda: exr.write_exr(tmp_path / "a.exr", image)) <= 2 * band + 64_000
    assert _peak_bytes(lambda: exr.read_exr(tmp_path / "a.exr")) <= image.nbytes + 2 * band + 64_000
    # A half-float file too: the library converts it to float32 band by band.
    half = {c: np.ascontiguousarray(image[..., i], dtype=np.float16) for i, c in enumerate("RGB")}
    _write_raw(tmp_path / "h.exr", half)
    assert _peak_bytes(lambda: exr.read_exr(tmp_path / "h.exr")) <= image.nbytes + 2 * band + 64_000


@pytest.mark.usefixtures("small_bands")
def test_rows_are_asked_for_once_each_top_first(tmp_path):
    image = _hdr_image(height=10).astype(np.float64)
    asked = []

    def rows(start, stop):
        asked.append((start, stop))
        return image[start:stop]

    exr.write_exr_rows(tmp_path / "r.exr", 10, 10, rows)
    assert asked == [(0, 4), (4, 8), (8, 10)]
    np.testing.assert_array_equal(exr.read_exr(tmp_path / "r.exr"), image.astype(np.float32))


@pytest.mark.usefixtures("small_bands")
def test_a_failing_row_source_leaves_no_file(tmp_path):
    def rows(start, stop):
        if start >= 4:
            raise DimredError("non-finite values")
        return np.zeros((stop - start, 3, 3), np.float32)

    with pytest.raises(DimredError, match="non-finite values"):
        exr.write_exr_rows(tmp_path / "r.exr", 10, 3, rows)
    with pytest.raises(ValueError, match="shape"):
        exr.write_exr_rows(tmp_path / "r.exr", 10, 3, lambda start, stop: np.zeros((stop - start, 4, 3)))
    assert os.listdir(tmp_path) == []


def _single_line_error(path) -> str:
    with pytest.raises(DimredError) as caught:
        exr.read_exr(path)
    message = str(caught.value)
    assert "\n" not in message and str(path) in message
    return message


def test_missing_file(tmp_path):
    assert "not found" in _single_line_error(tmp_path / "nope.exr")


def test_garbage_file(tmp_path):
    (tmp_path / "junk.exr").write_bytes(b"this is not an image" * 20)
    assert "not an OpenEXR file" in _single_line_error(tmp_path / "junk.exr")


def test_truncated_file_is_one_quiet_error(tmp_path, capfd):
    exr.write_exr(tmp_path / "full.exr", np.random.default_rng(0).random((64, 64, 3)).astype(np.float32))
    data = (tmp_path / "full.exr").read_bytes()
    (tmp_path / "cut.exr").write_bytes(data[: len(data) // 2])
    assert "cannot read EXR file" in _single_line_error(tmp_path / "cut.exr")
    # The library's own diagnostics went into the message, not onto the terminal.
    out, err = capfd.readouterr()
    assert out == "" and err == ""


def test_file_without_colour_channels(tmp_path):
    _write_raw(tmp_path / "y.exr", {"Y": np.ones((4, 4), np.float32)})
    assert "no R, G, B channels (channels: Y)" in _single_line_error(tmp_path / "y.exr")


def _failing_write_keeps(tmp_path, monkeypatch, output_file, expected: str, *, interface: str = "OutputFile"
                         ) -> None:
    """With `output_file` standing in for OpenEXR.OutputFile (the banded writer) or
    OpenEXR.File (the whole-image one), a write fails with `expected` in its message, and the
    file written before is left as it was, with no temporary beside it."""
    path = tmp_path / "keep.exr"
    old = _hdr_image()
    exr.write_exr(path, old)
    monkeypatch.setattr(exr.OpenEXR, interface, output_file)
    new = np.zeros((2, 2, 3), np.float32)
    with pytest.raises(DimredError, match=expected):
        if interface == "File":
            exr.write_exr(path, new)
        else:
            exr.write_exr_rows(path, 2, 2, lambda start, stop: new[start:stop])
    monkeypatch.undo()
    np.testing.assert_array_equal(exr.read_exr(path), old)
    assert os.listdir(tmp_path) == ["keep.exr"]


def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    class HalfWritingFile:
        """Writes part of a file, then fails like a full disk."""

        def __init__(self, target, header):
            self.target = target

        def writePixels(self, planes, rows):
            with open(self.target, "wb") as handle:
                handle.write(b"v/1\x01partial")
            raise OSError("No space left on device")

        def close(self):
            pass

    _failing_write_keeps(tmp_path, monkeypatch, HalfWritingFile, "No space left on device")


def test_a_whole_image_write_that_fails_or_is_cut_short_keeps_the_old_file(tmp_path, monkeypatch):
    real = exr.OpenEXR.File

    class FailingFile:
        """Writes part of a file, then fails like a full disk."""

        def __init__(self, header, channels):
            pass

        def write(self, target):
            with open(target, "wb") as handle:
                handle.write(b"v/1\x01partial")
            raise RuntimeError("No space left on device")

    class TruncatingFile:
        """The library's own writer, but the last bytes never reach the disk."""

        def __init__(self, header, channels):
            self.file = real(header, channels)

        def write(self, target):
            self.file.write(target)
            os.truncate(target, os.path.getsize(target) - 1)

    _failing_write_keeps(tmp_path, monkeypatch, FailingFile, "No space left on device", interface="File")
    _failing_write_keeps(tmp_path, monkeypatch, TruncatingFile, "incomplete", interface="File")


def test_a_file_cut_short_as_it_is_closed_is_not_kept(tmp_path, monkeypatch):
    real = exr.OpenEXR.OutputFile

    class LosingTheLastBytes:
        """The library's own writer, but the last bytes never reach the disk, as when the disk
        fills up while the file is closed (the library drops that failure)."""

        def __init__(self, target, header):
            self.target, self.file = target, real(target, header)

        def writePixels(self, planes, rows):
            self.file.writePixels(planes, rows)

        def close(self):
            self.file.close()
            os.truncate(self.target, os.path.getsize(self.target) - 1)

    _failing_write_keeps(tmp_path, monkeypatch, LosingTheLastBytes, "incomplete")


def test_write_into_missing_folder_is_an_error(tmp_path):
    with pytest.raises(DimredError, match="cannot write"):
        exr.write_exr(tmp_path / "missing" / "a.exr", np.zeros((2, 2, 3), np.float32))


def test_written_files_follow_the_umask(tmp_path):
    previous = os.umask(0o022)
    try:
        exr.write_exr(tmp_path / "a.exr", np.zeros((2, 2, 3), np.float32))
        exr.write_png(tmp_path / "a.png", np.zeros((2, 2), np.uint8))
    finally:
        os.umask(previous)
    assert (tmp_path / "a.exr").stat().st_mode & 0o777 == 0o644
    assert (tmp_path / "a.png").stat().st_mode & 0o777 == 0o644


def _decode_png(data: bytes) -> tuple[dict, np.ndarray]:
    """A minimal PNG reader for 8-bit, unfiltered (filter type 0) images."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    position, chunks = 8, {}
    while position < len(data):
        (length,) = struct.unpack(">I", data[position : position + 4])
        kind = data[position + 4 : position + 8]
        body = data[position + 8 : position + 8 + length]
        (crc,) = struct.unpack(">I", data[position + 8 + length : position + 12 + length])
        assert crc == zlib.crc32(kind + body)
        chunks[kind] = chunks.get(kind, b"") + body
        position += 12 + length
    width, height, depth, colour, _, _, _ = struct.unpack(">IIBBBBB", chunks[b"IHDR"])
    samples = {0: 1, 2: 3}[colour]
    raw = np.frombuffer(zlib.decompress(chunks[b"IDAT"]), np.uint8).reshape(height, 1 + width * samples)
    assert depth == 8 and np.all(raw[:, 0] == 0) and b"IEND" in chunks
    return {"width": width, "height": height, "colour": colour}, raw[:, 1:].reshape(height, width, samples)


@pytest.mark.parametrize("shape", [(5, 7), (5, 7, 3)])
def test_png_round_trip(tmp_path, shape):
    image = np.random.default_rng(1).integers(0, 256, size=shape, dtype=np.uint8)
    exr.write_png(tmp_path / "m.png", image)
    header, pixels = _decode_png((tmp_path / "m.png").read_bytes())
    assert (header["width"], header["height"]) == (7, 5)
    assert header["colour"] == (0 if len(shape) == 2 else 2)
    np.testing.assert_array_equal(pixels.reshape(shape), image)


def test_png_rejects_other_types(tmp_path):
    with pytest.raises(ValueError):
        exr.write_png(tmp_path / "m.png", np.zeros((4, 4), bool))
    with pytest.raises(ValueError):
        exr.write_png(tmp_path / "m.png", np.zeros((4, 4, 4), np.uint8))


def test_a_band_holds_a_chunk_for_each_of_the_librarys_threads(monkeypatch):
    monkeypatch.setattr(exr, "_codec_threads", lambda: 3)
    assert list(exr._bands(200, 1 << 18, chunk=32)) == [(0, 96), (96, 192), (192, 200)]
    monkeypatch.setattr(exr, "_codec_threads", lambda: 1)
    assert list(exr._bands(100, 1 << 18, chunk=32)) == [(0, 32), (32, 64), (64, 96), (96, 100)]


def test_the_librarys_threads_are_started_once_and_left_as_set(monkeypatch):
    monkeypatch.setattr(exr.OpenEXR, "global_thread_count", lambda: 5)
    monkeypatch.setattr(exr.OpenEXR, "set_global_thread_count", lambda n: pytest.fail("reset the library's threads"))
    assert exr._codec_threads() == 5


def test_library_calls_on_two_threads_leave_stdout_and_stderr_as_they_were(capfd):
    import sys
    import threading

    stdout, fd2 = sys.stdout, os.fstat(2)
    first_in, second_in, first_out = threading.Event(), threading.Event(), threading.Event()
    texts = {}

    def first():
        with exr._captured_library_messages() as printed:
            first_in.set()
            second_in.wait(5)
            print("from the first call")
        first_out.set()
        texts["first"] = printed

    def second():
        first_in.wait(5)
        with exr._captured_library_messages() as printed:
            second_in.set()
            first_out.wait(5)  # the first call ends while this one is still inside
            os.write(2, b"core message\n")
            texts["second"] = printed()

    threads = [threading.Thread(target=first), threading.Thread(target=second)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(10)
    assert sys.stdout is stdout
    assert (os.fstat(2).st_ino, os.fstat(2).st_dev) == (fd2.st_ino, fd2.st_dev)
    assert "core message" in texts["second"] and "from the first call" in texts["second"]
    print("after")
    assert capfd.readouterr().out == "after\n"
