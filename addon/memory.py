"""The memory a run needs, from the panorama's size alone, and the memory the machine has free.

A removal of a 16384 x 8192 panorama holds gigabytes; one that cannot fit is refused before
any work starts, with a message saying what to do, rather than killed by the operating system
halfway. Where the free memory cannot be found out, nothing is refused.
"""
from __future__ import annotations

import ctypes
import os
import sys

from .errors import DimredError
from .quality import PRESETS

# Bytes per full-resolution pixel, measured on removals of 8192 x 4096 and 16384 x 8192
# panoramas (peak resident memory against the pixel count: 2.3 and 4.7 GB at balanced, Blender
# included, so about 24 bytes a pixel on top of a fixed part; 8 more are kept as a margin; final:
# 2.8 GB at 8192 x 4096).
INPUT_BYTES_PER_PIXEL = 12  # the panorama, float32 RGB
DIFFERENCE_BYTES_PER_PIXEL = 12  # the difference image, float32 RGB
BAND_BYTES_PER_PIXEL = 8  # the hidden mask, per-pixel flags and the bands in flight
#: Bytes the working-resolution solve, the object's window and Blender itself hold whatever the
#: panorama's size, per quality preset (measured as above: the intercept of peak memory against
#: pixel count; final solves at twice the working width).
SOLVE_BYTES = {"draft": 1_300_000_000, "balanced": 1_400_000_000, "final": 2_000_000_000}
#: Bytes the solve adds per pixel of a working copy wider than its preset's: at 8192 x 4096,
#: balanced solved at 512, 1024 and 2048 wide peaked at 1.50, 1.63 and 2.08 GiB
#: (`bench_scale.py --working-widths`), 310-355 bytes a working pixel; the rest is a margin.
WORKING_BYTES_PER_PIXEL = 400

_GB = 1e9


def required_bytes(width: int, height: int, *, quality: str, working_width: int | None = None) -> int:
    """The memory a removal of a `width` x `height` panorama at `quality` needs at its peak,
    with the light solved at most `working_width` wide (default: the preset's)."""
    if quality not in SOLVE_BYTES:
        raise DimredError(f"unknown quality '{quality}': choose one of {', '.join(SOLVE_BYTES)}")
    per_pixel = INPUT_BYTES_PER_PIXEL + DIFFERENCE_BYTES_PER_PIXEL + BAND_BYTES_PER_PIXEL
    solve = SOLVE_BYTES[quality]
    if working_width is not None:
        # A narrower copy than the preset's is not counted as a saving: the fixed part was
        # measured at the preset's width only, and an estimate must not fall short.
        wider = _working_pixels(width, working_width) - _working_pixels(width, PRESETS[quality].working_width)
        solve += WORKING_BYTES_PER_PIXEL * max(0, wider)
    return solve + per_pixel * int(width) * int(height)


def _working_pixels(width: int, working_width: int) -> int:
    side = min(int(width), int(working_width))
    return side * (side // 2)


def check_fits(width: int, height: int, *, quality: str, working_width: int | None = None,
               available: int | None = None) -> None:
    """DimredError unless a removal of a `width` x `height` panorama fits in `available` bytes
    (default: what `available_bytes` finds; nothing is refused where it finds nothing)."""
    needed = required_bytes(width, height, quality=quality, working_width=working_width)
    if available is None:
        available = available_bytes()
    if available is not None and needed > available:
        raise DimredError(
            f"a {width}x{height} panorama needs about {needed / _GB:.1f} GB of memory at quality '{quality}' "
            f"but only {available / _GB:.1f} GB is available: close other programs or use a smaller copy "
            "of the panorama" + ("" if working_width is None else " or a narrower working width")
        )


def available_bytes() -> int | None:
    """The memory the machine can give this process now without swapping, or None when the
    system does not say."""
    if sys.platform.startswith("linux"):
        return _linux_available()
    if sys.platform == "darwin":
        return _macos_available()
    if sys.platform == "win32":
        return _windows_available()
    return None


_MEMINFO = "/proc/meminfo"


def _linux_available() -> int | None:
    """MemAvailable of /proc/meminfo: free memory plus the caches the kernel can drop."""
    try:
        with open(_MEMINFO, encoding="ascii") as lines:
            for line in lines:
                name, _, value = line.partition(":")
                if name == "MemAvailable":
                    kilobytes, unit = value.split()
                    return int(kilobytes) * 1024 if unit == "kB" else None
    except (OSError, ValueError):
        return None
    # Kernels before 3.14 do not estimate it.
    return None


class _VmStatistics64(ctypes.Structure):
    """struct vm_statistics64 of <mach/vm_statistics.h>."""

    _fields_ = [
        ("free_count", ctypes.c_uint32),
        ("active_count", ctypes.c_uint32),
        ("inactive_count", ctypes.c_uint32),
        ("wire_count", ctypes.c_uint32),
        ("zero_fill_count", ctypes.c_uint64),
        ("reactivations", ctypes.c_uint64),
        ("pageins", ctypes.c_uint64),
        ("pageouts", ctypes.c_uint64),
        ("faults", ctypes.c_uint64),
        ("cow_faults", ctypes.c_uint64),
        ("lookups", ctypes.c_uint64),
        ("hits", ctypes.c_uint64),
        ("purges", ctypes.c_uint64),
        ("purgeable_count", ctypes.c_uint32),
        ("speculative_count", ctypes.c_uint32),
        ("decompressions", ctypes.c_uint64),
        ("compressions", ctypes.c_uint64),
        ("swapins", ctypes.c_uint64),
        ("swapouts", ctypes.c_uint64),
        ("compressor_page_count", ctypes.c_uint32),
        ("throttled_count", ctypes.c_uint32),
        ("external_page_count", ctypes.c_uint32),
        ("internal_page_count", ctypes.c_uint32),
        ("total_uncompressed_pages_in_compressor", ctypes.c_uint64),
    ]


_HOST_VM_INFO64 = 4
_KERN_SUCCESS = 0


def _macos_available() -> int | None:
    """Free plus inactive pages (what macOS hands out before it compresses or swaps), from
    the Mach kernel's host_statistics64."""
    try:
        library = ctypes.CDLL("/usr/lib/libSystem.B.dylib")
        host = library.mach_host_self()
        statistics = _VmStatistics64()
        count = ctypes.c_uint32(ctypes.sizeof(statistics) // ctypes.sizeof(ctypes.c_int32))
        status = library.host_statistics64(host, _HOST_VM_INFO64, ctypes.byref(statistics), ctypes.byref(count))
        page = os.sysconf("SC_PAGE_SIZE")
    except (OSError, AttributeError, ValueError):
        return None
    if status != _KERN_SUCCESS:
        return None
    return (statistics.free_count + statistics.inactive_count) * page


class _MemoryStatusEx(ctypes.Structure):
    """MEMORYSTATUSEX of <sysinfoapi.h>."""

    _fields_ = [
        ("dwLength", ctypes.c_uint32),
        ("dwMemoryLoad", ctypes.c_uint32),
        ("ullTotalPhys", ctypes.c_uint64),
        ("ullAvailPhys", ctypes.c_uint64),
        ("ullTotalPageFile", ctypes.c_uint64),
        ("ullAvailPageFile", ctypes.c_uint64),
        ("ullTotalVirtual", ctypes.c_uint64),
        ("ullAvailVirtual", ctypes.c_uint64),
        ("ullAvailExtendedVirtual", ctypes.c_uint64),
    ]


def _windows_available() -> int | None:
    """ullAvailPhys of GlobalMemoryStatusEx: physical memory free or on standby."""
    status = _MemoryStatusEx()
    status.dwLength = ctypes.sizeof(status)
    try:
        succeeded = ctypes.WinDLL("kernel32").GlobalMemoryStatusEx(ctypes.byref(status))
    except (OSError, AttributeError):
        return None
    return int(status.ullAvailPhys) if succeeded else None
