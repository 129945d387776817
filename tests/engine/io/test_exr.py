"""EXR and PNG files: what the add-on writes reads back exactly, other EXR layouts read right,
bad files give one clear error line, and a failed write leaves the old file alone."""
from __future__ import annotations

import os
import struct
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


def test_failed_write_keeps_the_old_file_and_leaves_no_temporary(tmp_path, monkeypatch):
    path = tmp_path / "keep.exr"
    old = _hdr_image()
    exr.write_exr(path, old)

    class HalfWritingFile:
        """Stands in for OpenEXR.File: writes part of a file, then fails like a full disk."""

        def __init__(self, header, channels):
            pass

        def write(self, target):
            with open(target, "wb") as handle:
                handle.write(b"v/1\x01partial")
            raise RuntimeError("No space left on device")

    monkeypatch.setattr(exr.OpenEXR, "File", HalfWritingFile)
    with pytest.raises(DimredError, match="No space left on device"):
        exr.write_exr(path, np.zeros((2, 2, 3), np.float32))
    monkeypatch.undo()
    np.testing.assert_array_equal(exr.read_exr(path), old)
    assert os.listdir(tmp_path) == ["keep.exr"]


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
