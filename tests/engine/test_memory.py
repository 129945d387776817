"""The memory estimate and the refusal of a run that cannot fit: the arithmetic, the message,
each system's way of saying what is free, and no refusal where none says."""
from __future__ import annotations

import ctypes
import sys

import pytest

from addon import memory
from addon.errors import DimredError
from addon.quality import PRESETS

GB = 1_000_000_000


def test_every_preset_has_a_solve_size():
    assert set(memory.SOLVE_BYTES) == set(PRESETS)


def test_required_bytes_grow_with_the_pixels_over_the_solve():
    per_pixel = memory.INPUT_BYTES_PER_PIXEL + memory.DIFFERENCE_BYTES_PER_PIXEL + memory.BAND_BYTES_PER_PIXEL
    for quality, solve in memory.SOLVE_BYTES.items():
        assert memory.required_bytes(8192, 4096, quality=quality) == solve + per_pixel * 8192 * 4096
    # Four times the pixels: four times the per-pixel share, the same solve.
    small = memory.required_bytes(8192, 4096, quality="balanced")
    large = memory.required_bytes(16384, 8192, quality="balanced")
    assert large - memory.SOLVE_BYTES["balanced"] == 4 * (small - memory.SOLVE_BYTES["balanced"])
    assert memory.required_bytes(8192, 4096, quality="final") > small
    with pytest.raises(DimredError, match="unknown quality 'best'"):
        memory.required_bytes(8, 4, quality="best")


def test_a_wider_working_copy_than_the_presets_adds_its_pixels():
    balanced = memory.required_bytes(8192, 4096, quality="balanced")
    assert memory.required_bytes(8192, 4096, quality="balanced", working_width=1024) == balanced
    wider = memory.required_bytes(8192, 4096, quality="balanced", working_width=2048)
    assert wider - balanced == memory.WORKING_BYTES_PER_PIXEL * (2048 * 1024 - 1024 * 512) > 0
    # A narrower one saves what its solve saves, which the estimate does not count on.
    assert memory.required_bytes(8192, 4096, quality="final", working_width=512) == memory.required_bytes(
        8192, 4096, quality="final")
    # A panorama narrower than the working width is solved at its own size.
    assert memory.required_bytes(1536, 768, quality="balanced", working_width=4096) - memory.required_bytes(
        1536, 768, quality="balanced") == memory.WORKING_BYTES_PER_PIXEL * (1536 * 768 - 1024 * 512)
    assert memory.required_bytes(800, 400, quality="balanced", working_width=4096) == memory.required_bytes(
        800, 400, quality="balanced")


def test_a_run_that_does_not_fit_is_refused_with_what_to_do():
    needed = memory.required_bytes(16384, 8192, quality="balanced")
    with pytest.raises(DimredError) as refused:
        memory.check_fits(16384, 8192, quality="balanced", available=2_100_000_000)
    assert str(refused.value) == (
        f"a 16384x8192 panorama needs about {needed / GB:.1f} GB of memory at quality 'balanced' but only "
        "2.1 GB is available: close other programs or use a smaller copy of the panorama"
    )
    memory.check_fits(16384, 8192, quality="balanced", available=needed)
    with pytest.raises(DimredError):
        memory.check_fits(16384, 8192, quality="balanced", available=needed - 1)
    with pytest.raises(DimredError, match=r"use a smaller copy of the panorama or a narrower working width$"):
        memory.check_fits(16384, 8192, quality="balanced", working_width=4096, available=needed)


def test_the_machine_is_asked_when_no_figure_is_given(monkeypatch):
    monkeypatch.setattr(memory, "available_bytes", lambda: 1000)
    with pytest.raises(DimredError, match=r"only 0\.0 GB is available"):
        memory.check_fits(64, 32, quality="draft")


def test_nothing_is_refused_where_the_system_does_not_say(monkeypatch):
    monkeypatch.setattr(sys, "platform", "sunos5")
    assert memory.available_bytes() is None
    memory.check_fits(1 << 20, 1 << 19, quality="final")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads this machine's /proc/meminfo")
def test_this_linux_machine_says_how_much_is_free():
    with open("/proc/meminfo", encoding="ascii") as lines:
        total = next(int(line.split()[1]) * 1024 for line in lines if line.startswith("MemTotal:"))
    assert 0 < memory.available_bytes() <= total


@pytest.mark.parametrize(
    "text, expected",
    [
        ("MemTotal:       16000000 kB\nMemFree:         1000000 kB\nMemAvailable:    5078125 kB\n", 5_200_000_000),
        # Kernels before 3.14 have no MemAvailable; a file that cannot be parsed gives nothing either.
        ("MemTotal:       16000000 kB\nMemFree:         1000000 kB\n", None),
        ("MemAvailable: lots\n", None),
    ],
)
def test_linux_memavailable(monkeypatch, tmp_path, text, expected):
    (tmp_path / "meminfo").write_text(text)
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setattr(memory, "_MEMINFO", str(tmp_path / "meminfo"))
    assert memory.available_bytes() == expected


def test_linux_without_proc(monkeypatch, tmp_path):
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setattr(memory, "_MEMINFO", str(tmp_path / "missing"))
    assert memory.available_bytes() is None


class _FakeMach:
    """libSystem's host_statistics64, filling in page counts."""

    def __init__(self, status=0):
        self.status = status

    def mach_host_self(self):
        return 7

    def host_statistics64(self, host, flavor, statistics, count):
        assert (host, flavor, count._obj.value) == (7, 4, 38)
        statistics._obj.free_count, statistics._obj.inactive_count, statistics._obj.active_count = 1000, 3000, 9000
        return self.status


def test_macos_free_and_inactive_pages(monkeypatch):
    monkeypatch.setattr(sys, "platform", "darwin")
    monkeypatch.setattr(ctypes, "CDLL", lambda path: _FakeMach())
    monkeypatch.setattr(memory.os, "sysconf", lambda name: 16384)
    assert memory.available_bytes() == 4000 * 16384
    monkeypatch.setattr(ctypes, "CDLL", lambda path: _FakeMach(status=5))
    assert memory.available_bytes() is None


def test_macos_without_the_mach_calls(monkeypatch):
    def missing(path):
        raise OSError(f"{path}: cannot open shared object file")

    monkeypatch.setattr(sys, "platform", "darwin")
    monkeypatch.setattr(ctypes, "CDLL", missing)
    assert memory.available_bytes() is None


class _FakeKernel32:
    def __init__(self, succeeds=True):
        self.succeeds = succeeds

    def GlobalMemoryStatusEx(self, status):  # the Windows API's name
        assert status._obj.dwLength == 64
        status._obj.ullAvailPhys = 6_000_000_000
        return 1 if self.succeeds else 0


def test_windows_available_physical_memory(monkeypatch):
    monkeypatch.setattr(sys, "platform", "win32")
    monkeypatch.setattr(ctypes, "WinDLL", lambda name: _FakeKernel32(), raising=False)
    assert memory.available_bytes() == 6_000_000_000
    monkeypatch.setattr(ctypes, "WinDLL", lambda name: _FakeKernel32(succeeds=False), raising=False)
    assert memory.available_bytes() is None


def test_windows_without_kernel32(monkeypatch):
    monkeypatch.setattr(sys, "platform", "win32")
    monkeypatch.delattr(ctypes, "WinDLL", raising=False)
    assert memory.available_bytes() is None
