"""Image files for the harness: EXR read/write (OpenEXR, top row first) and tonemapped PNGs.

EXR files here are what the engine reads and writes: RGB float32, row 0 = top of the
panorama. PNGs are for looking at renders only; they need no imaging library.
"""
from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np
import OpenEXR


def read_exr(path: str | Path) -> np.ndarray:
    """(H, W, 3) float32 linear RGB, row 0 at the top; alpha and other channels are dropped."""
    with OpenEXR.File(str(path), separate_channels=True) as f:
        ch = f.channels()
        missing = [c for c in "RGB" if c not in ch]
        if missing:
            raise ValueError(f"{path}: no channel(s) {missing}, has {sorted(ch)}")
        return np.stack([ch[c].pixels for c in "RGB"], axis=-1).astype(np.float32)


def write_exr(path: str | Path, rgb: np.ndarray) -> None:
    """Write (H, W, 3) linear RGB as an RGB float32 ZIP-compressed EXR, row 0 at the top."""
    rgb = np.ascontiguousarray(rgb, dtype=np.float32)
    if rgb.ndim != 3 or rgb.shape[2] != 3:
        raise ValueError(f"expected (H, W, 3), got {rgb.shape}")
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, {"RGB": rgb}) as f:
        f.write(str(path))


def tonemap(rgb: np.ndarray, exposure: float) -> np.ndarray:
    """8-bit sRGB for display: scale by `exposure`, Reinhard x / (1 + x), sRGB transfer curve."""
    x = np.maximum(np.asarray(rgb, dtype=np.float64) * exposure, 0.0)
    x = x / (1.0 + x)
    srgb = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)
    return np.clip(np.round(srgb * 255.0), 0, 255).astype(np.uint8)


def auto_exposure(rgb: np.ndarray) -> float:
    """Exposure that puts the median luminance at 0.25 (before the Reinhard curve)."""
    y = rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722
    return 0.25 / max(float(np.median(y)), 1e-12)


def write_png(path: str | Path, rgb8: np.ndarray) -> None:
    """Write (H, W, 3) uint8 as an 8-bit RGB PNG."""
    rgb8 = np.ascontiguousarray(rgb8, dtype=np.uint8)
    h, w = rgb8.shape[:2]
    # Each scanline starts with filter type 0 (none).
    raw = np.concatenate([np.zeros((h, 1), np.uint8), rgb8.reshape(h, w * 3)], axis=1)

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    png = (b"\x89PNG\r\n\x1a\n"
           + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
           + chunk(b"IDAT", zlib.compress(raw.tobytes(), 6))
           + chunk(b"IEND", b""))
    Path(path).write_bytes(png)
