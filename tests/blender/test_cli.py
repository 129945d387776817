"""The command line (`python -m addon.cli`, `blender -c dimred`) with a stand-in engine: the files
a run writes, one error line and exit status 2 for each kind of bad input, and nothing on disk
unless the run succeeds."""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

from addon import memory, pipeline
from addon.blender import cli, reader
from addon.callbacks import NO_CALLBACKS
from addon.errors import DimredError
from addon.io import exr
from addon.io.exr import read_exr, write_exr
from addon.radiance import round_to_stored_precision
from addon.relocation.fixedview import Move
from addon.removal import RemovalResult
from tests.blender.tiny_scene import environment_world

pytestmark = pytest.mark.usefixtures("fresh_blender")

ROOT = Path(__file__).resolve().parents[2]
HDRI = np.random.default_rng(11).random((8, 16, 3)).astype(np.float32)


def _plane(name: str, size: float, z: float) -> bpy.types.Object:
    mesh = bpy.data.meshes.new(name)
    h = size / 2
    mesh.from_pydata([(-h, -h, z), (h, -h, z), (h, h, z), (-h, h, z)], [], [(0, 1, 2, 3)])
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _save_scene(folder: Path, image_path: Path | None = None) -> Path:
    """A room floor, a box on it, a camera and a lamp, lit by HDRI; saved as folder/room.blend."""
    if image_path is None:
        image_path = folder / "probe.exr"
        write_exr(image_path, HDRI)
    scene = bpy.context.scene
    _plane("Floor", 4.0, 0.0)
    _plane("Box", 0.6, 0.3)
    scene.collection.objects.link(bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera")))
    scene.collection.objects.link(bpy.data.objects.new("Lamp", bpy.data.lights.new("Lamp", 'POINT')))
    image = bpy.data.images.new("probe", 16, 8, float_buffer=True)
    image.source = 'FILE'
    image.filepath = str(image_path)
    scene.world, _ = environment_world(bpy, "Probe", image)
    path = folder / "room.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    return path


class BandedResult(RemovalResult):
    """A removal's result whose edited panorama can only be had by rows, as a writer that never
    holds it whole takes it."""

    @property
    def edited(self):
        raise AssertionError("the whole edited panorama was built")


class FakeEngine:
    """Stands in for `pipeline.remove_object`; records its call, returns a fixed result."""

    def __init__(self, filled: bool = True, difference: float = 0.25, error: str | None = None):
        self.filled, self.difference, self.error = filled, difference, error
        self.calls: list[dict] = []

    def __call__(self, scene_data, object_name, *, planes=(), quality="balanced", callbacks=NO_CALLBACKS, mask=None,
                 align=False, fit_height=False, **overrides):
        progress = callbacks.progress
        self.calls.append(
            {"scene": scene_data, "object": object_name, "planes": planes, "quality": quality, "progress": progress,
             "mask": mask, "align": align, "fit_height": fit_height, "overrides": overrides}
        )
        if progress is not None:
            progress("synthesis", 0.5)
        if self.error is not None:
            raise DimredError(self.error)
        difference = np.full_like(scene_data.hdri, self.difference)
        mask = np.zeros(scene_data.hdri.shape[:2], bool)
        mask[2:4, 5:9] = True
        report = {
            "seconds": {"synthesis": 0.01, "total": 0.02},
            "skipped": [{"stage": "relocation", "reason": "not asked"}],
            "warnings": ["3 pixels clamped"],
            "guards": {"reflectance_clamped": 3},
            "hidden_region_filled": self.filled,
        }
        return BandedResult(difference=difference, hidden_mask=mask, report=report, hdri=scene_data.hdri)


@pytest.fixture
def engine(monkeypatch):
    fake = FakeEngine()
    monkeypatch.setattr(pipeline, "remove_object", fake)
    return fake


@pytest.fixture
def room(tmp_path) -> Path:
    return _save_scene(tmp_path)


def _lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip()]


def test_success_writes_the_three_files(room, engine, monkeypatch, tmp_path, capfd):
    monkeypatch.setattr(exr, "BAND_ROWS", 3)  # the 8 rows in three bands
    out = tmp_path / "result"
    code = cli.main(["remove", str(room), "--object", "Box", "--plane", "Floor", "--out", str(out),
                     "--quality", "draft"])
    stdout, stderr = capfd.readouterr()
    assert code == 0
    assert sorted(os.listdir(out)) == ["difference.exr", "edited.exr", "report.json"]
    np.testing.assert_array_equal(read_exr(out / "difference.exr"), np.full_like(HDRI, 0.25))
    # The changed pixels (all of them here) are stored to the difference's precision.
    np.testing.assert_array_equal(read_exr(out / "edited.exr"), round_to_stored_precision(HDRI + np.float32(0.25)))
    report = json.loads((out / "report.json").read_text())
    assert report["seconds"]["synthesis"] == 0.01 and report["seconds"]["total"] >= report["seconds"]["read_scene"]
    assert report["guards"] == {"reflectance_clamped": 3}
    assert _lines(stdout) == [line for line in _lines(stdout) if line.startswith("dimred: removed 'Box' in ")]
    assert len(_lines(stdout)) == 1 and str(out) in stdout
    assert _lines(stderr) == ["dimred: warning: 3 pixels clamped"]
    call = engine.calls[0]
    assert (call["object"], call["planes"], call["quality"], call["progress"]) == ("Box", ["Floor"], "draft", None)
    assert call["overrides"] == {}
    np.testing.assert_array_equal(call["scene"].hdri, HDRI)
    assert call["scene"].object_names == ["Box", "Floor"]


def test_unfilled_hidden_region_writes_the_mask(room, monkeypatch, tmp_path):
    monkeypatch.setattr(pipeline, "remove_object", FakeEngine(filled=False))
    out = tmp_path / "result"
    assert cli.main(["remove", str(room), "--object", "Box", "--out", str(out)]) == 0
    assert sorted(os.listdir(out)) == ["difference.exr", "edited.exr", "hidden_mask.png", "report.json"]
    # A later run that filled the region removes the stale mask.
    monkeypatch.setattr(pipeline, "remove_object", FakeEngine(filled=True))
    assert cli.main(["remove", str(room), "--object", "Box", "--out", str(out)]) == 0
    assert "hidden_mask.png" not in os.listdir(out)


def test_verbose_progress_and_centre(room, engine, tmp_path, capfd):
    code = cli.main(["remove", str(room), "--object", "Box", "--out", str(tmp_path / "o"),
                     "--center", "0.5", "-1", "1.5", "--verbose"])
    _, stderr = capfd.readouterr()
    assert code == 0
    assert engine.calls[0]["scene"].center.tolist() == [0.5, -1.0, 1.5]
    assert "dimred:  50.0% synthesis" in _lines(stderr)
    assert "dimred: note: probe centre (0.5, -1, 1.5) as given" in _lines(stderr)


def test_blender_command_uses_the_open_file(room, engine, tmp_path, capfd):
    bpy.ops.wm.open_mainfile(filepath=str(room), load_ui=False)
    capfd.readouterr()
    out = tmp_path / "from-blender"
    assert cli.blender_command(["remove", "--object", "Box", "--out", str(out)]) == 0
    assert (out / "difference.exr").is_file()


def test_blender_command_without_a_file(engine, tmp_path, capfd):
    assert cli.blender_command(["remove", "--object", "Box", "--out", str(tmp_path / "o")]) == 2
    assert _lines(capfd.readouterr().err) == ["dimred: error: no .blend file is open: pass SCENE.blend"]


def _bad_cases(tmp_path: Path, room: Path) -> dict[str, tuple[list[str], str]]:
    garbage = tmp_path / "garbage.blend"
    garbage.write_bytes(b"BLENDER? no" * 50)
    return {
        "missing blend": ([str(tmp_path / "nowhere.blend"), "--object", "Box"], "no such .blend file"),
        "garbage blend": ([str(garbage), "--object", "Box"], "cannot open"),
        "unknown object": ([str(room), "--object", "Chair"], "no object named 'Chair' in scene 'Scene'"),
        "not a mesh": ([str(room), "--object", "Lamp"], "'Lamp' is a LIGHT, not a mesh"),
        "unknown plane": ([str(room), "--object", "Box", "--plane", "Wall"], "no object named 'Wall'"),
        "camera plane": ([str(room), "--object", "Box", "--plane", "Camera"], "'Camera' is a CAMERA, not a mesh"),
        "object as plane": ([str(room), "--object", "Box", "--plane", "Box"], "cannot also be a --plane"),
    }


BAD = ["missing blend", "garbage blend", "unknown object", "not a mesh", "unknown plane", "camera plane",
       "object as plane"]


def _assert_failed_cleanly(code: int, stderr: str, expected: str, out: Path, before: dict[str, bytes] | None) -> None:
    assert code == 2
    lines = _lines(stderr)
    assert len(lines) == 1 and lines[0].startswith("dimred: error: "), lines
    assert expected in lines[0]
    if before is None:
        assert not out.exists()
    else:
        assert {name: (out / name).read_bytes() for name in os.listdir(out)} == before
    assert not [name for name in os.listdir(out.parent) if name.startswith(".dimred-")]  # no staging left


@pytest.mark.parametrize("case", BAD)
def test_bad_input_is_one_error_line_and_no_files(room, engine, tmp_path, capfd, case):
    arguments, expected = _bad_cases(tmp_path, room)[case]
    out = tmp_path / "result"
    code = cli.main(["remove", *arguments, "--out", str(out)])
    stdout, stderr = capfd.readouterr()
    _assert_failed_cleanly(code, stderr, expected, out, None)
    assert stdout == ""
    assert not engine.calls


@pytest.mark.parametrize("case", ["unknown object", "garbage blend"])
def test_bad_input_leaves_earlier_results_intact(room, engine, tmp_path, capfd, case):
    out = tmp_path / "result"
    assert cli.main(["remove", str(room), "--object", "Box", "--out", str(out)]) == 0
    before = {name: (out / name).read_bytes() for name in os.listdir(out)}
    capfd.readouterr()
    arguments, expected = _bad_cases(tmp_path, room)[case]
    code = cli.main(["remove", *arguments, "--out", str(out)])
    _assert_failed_cleanly(code, capfd.readouterr().err, expected, out, before)


def test_missing_world_image(tmp_path, engine, capfd):
    room = _save_scene(tmp_path, image_path=tmp_path / "gone.exr")
    out = tmp_path / "result"
    code = cli.main(["remove", str(room), "--object", "Box", "--out", str(out)])
    _assert_failed_cleanly(code, capfd.readouterr().err, "cannot load image 'probe': file not found", out, None)


@pytest.mark.parametrize(
    "fake, expected",
    [
        (FakeEngine(error="the HDRI has 12 NaN pixels: fix the file"), "the HDRI has 12 NaN pixels: fix the file"),
        (FakeEngine(difference=float("nan")), "non-finite values in difference.exr"),
    ],
)
def test_engine_failure_writes_nothing(room, monkeypatch, tmp_path, capfd, fake, expected):
    monkeypatch.setattr(pipeline, "remove_object", fake)
    out = tmp_path / "result"
    code = cli.main(["remove", str(room), "--object", "Box", "--out", str(out)])
    _assert_failed_cleanly(code, capfd.readouterr().err, expected, out, None)


def test_failed_write_leaves_earlier_results_intact(room, engine, monkeypatch, tmp_path, capfd):
    out = tmp_path / "result"
    assert cli.main(["remove", str(room), "--object", "Box", "--out", str(out)]) == 0
    before = {name: (out / name).read_bytes() for name in os.listdir(out)}
    capfd.readouterr()
    real_write = exr.write_exr_rows

    def disk_full_at_second_image(path, height, width, rows):
        if os.path.basename(path) == "edited.exr":
            raise DimredError(f"cannot write {path}: No space left on device")
        real_write(path, height, width, rows)

    monkeypatch.setattr(exr, "write_exr_rows", disk_full_at_second_image)
    monkeypatch.setattr(pipeline, "remove_object", FakeEngine(difference=1.0))
    code = cli.main(["remove", str(room), "--object", "Box", "--out", str(out)])
    _assert_failed_cleanly(code, capfd.readouterr().err, "No space left on device", out, before)


def test_non_finite_values_in_a_later_band_write_nothing(room, monkeypatch, tmp_path, capfd):
    class LastRowBroken(FakeEngine):
        def __call__(self, scene_data, object_name, **options):
            result = super().__call__(scene_data, object_name, **options)
            result.difference[-1, -1, 2] = np.inf
            return result

    monkeypatch.setattr(exr, "BAND_ROWS", 3)
    monkeypatch.setattr(pipeline, "remove_object", LastRowBroken())
    out = tmp_path / "result"
    code = cli.main(["remove", str(room), "--object", "Box", "--out", str(out)])
    _assert_failed_cleanly(code, capfd.readouterr().err, "non-finite values in difference.exr", out, None)


def test_a_panorama_too_big_for_the_free_memory_is_refused_before_it_is_read(room, engine, monkeypatch, tmp_path,
                                                                           capfd):
    monkeypatch.setattr(memory, "available_bytes", lambda: 100_000_000)

    def pixels_read(path):
        raise AssertionError(f"the pixels of {path} were read")

    monkeypatch.setattr(reader, "read_exr", pixels_read)
    blend = room.read_bytes()
    out = tmp_path / "result"
    code = cli.main(["remove", str(room), "--object", "Box", "--out", str(out), "--quality", "final"])
    needed = memory.required_bytes(16, 8, quality="final") / 1e9
    _assert_failed_cleanly(code, capfd.readouterr().err,
                           f"a 16x8 panorama needs about {needed:.1f} GB of memory at quality 'final' but only 0.1 GB "
                           "is available: close other programs or use a smaller copy of the panorama", out, None)
    assert not engine.calls
    assert room.read_bytes() == blend


def test_the_working_width_reaches_the_engine_and_the_memory_check(room, engine, monkeypatch, tmp_path):
    checked = []
    monkeypatch.setattr(memory, "check_fits", lambda *size, **options: checked.append((size, options)))
    out = tmp_path / "result"
    assert cli.main(["remove", str(room), "--object", "Box", "--out", str(out), "--working-width", "512"]) == 0
    assert engine.calls[0]["overrides"] == {"working_width": 512}
    assert checked == [((16, 8), {"quality": "balanced", "working_width": 512})]


def test_out_is_a_file(room, engine, tmp_path, capfd):
    out = tmp_path / "taken"
    out.write_text("mine")
    assert cli.main(["remove", str(room), "--object", "Box", "--out", str(out)]) == 2
    assert _lines(capfd.readouterr().err) == [f"dimred: error: --out {out} is a file, not a folder"]
    assert out.read_text() == "mine"


@pytest.mark.parametrize(
    "arguments",
    [[], ["remove"], ["remove", "x.blend", "--out", "o"],
     ["remove", "x.blend", "--object", "Box", "--out", "o", "--quality", "best"],
     *(["remove", "x.blend", "--object", "Box", "--out", "o", "--working-width", w] for w in ("1023", "64", "wide")),
     ["align", "x.blend", "--object", "Box", "--out", "o", "--working-width", "512"]],
)
def test_usage_errors_exit_2(arguments, engine, capfd):
    assert cli.main(arguments) == 2
    assert "usage:" in capfd.readouterr().err


def test_help_describes_the_presets():
    result = subprocess.run([sys.executable, "-m", "addon.cli", "--help"], cwd=ROOT, capture_output=True, text=True)
    assert result.returncode == 0
    for text in ("remove", "draft", "fastest", "balanced", "default", "final", "most accurate", "--center"):
        assert text in result.stdout
    subcommand = subprocess.run([sys.executable, "-m", "addon.cli", "remove", "--help"], cwd=ROOT,
                                capture_output=True, text=True)
    assert subcommand.returncode == 0 and "--quality {draft,balanced,final}" in subcommand.stdout


def test_module_entry_point_reports_one_line(tmp_path):
    """The real process: exit status 2 and exactly one line on stderr, nothing on stdout."""
    result = subprocess.run(
        [sys.executable, "-m", "addon.cli", "remove", str(tmp_path / "none.blend"), "--object", "Box",
         "--out", str(tmp_path / "o")],
        cwd=ROOT,
        capture_output=True,
        text=True,
        # Blender sets OCIO in this process's C environment, and a child told of it logs so.
        env=dict(os.environ),
    )
    assert result.returncode == 2
    assert _lines(result.stderr) == [f"dimred: error: no such .blend file: {tmp_path / 'none.blend'}"]
    assert result.stdout == ""
    assert not (tmp_path / "o").exists()


class FakeRelocation(FakeEngine):
    """Stands in for `pipeline.relocate_object`; records the move too."""

    def __call__(self, scene_data, object_name, move, *, planes=(), quality="balanced", callbacks=NO_CALLBACKS,
                 **options):
        result = super().__call__(scene_data, object_name, planes=planes, quality=quality, callbacks=callbacks,
                                  **options)
        self.calls[-1]["move"] = move
        return result


@pytest.fixture
def relocation(monkeypatch):
    fake = FakeRelocation()
    monkeypatch.setattr(pipeline, "relocate_object", fake)
    return fake


def test_relocate_passes_the_move_and_writes_the_three_files(room, relocation, tmp_path, capfd):
    out = tmp_path / "moved"
    code = cli.main(["relocate", str(room), "--object", "Box", "--yaw", "-40", "--distance-scale", "1.3",
                     "--out", str(out)])
    stdout, _ = capfd.readouterr()
    assert code == 0
    assert sorted(os.listdir(out)) == ["difference.exr", "edited.exr", "report.json"]
    assert relocation.calls[0]["move"] == Move(-40.0, 1.3)
    assert _lines(stdout)[0].startswith("dimred: moved 'Box' in ")


def test_relocate_through_the_blender_command(room, relocation, tmp_path):
    bpy.ops.wm.open_mainfile(filepath=str(room), load_ui=False)
    out = tmp_path / "from-blender"
    assert cli.blender_command(["relocate", "--object", "Box", "--yaw", "15", "--out", str(out),
                                "--working-width", "2048"]) == 0
    assert relocation.calls[0]["move"] == Move(15.0, 1.0)
    assert relocation.calls[0]["overrides"] == {"working_width": 2048}


@pytest.mark.parametrize("scale, expected", [("0", "positive number, got 0.0"), ("-1.3", "got -1.3"),
                                             ("nan", "got nan")])
def test_relocate_refuses_a_distance_factor_not_above_zero(room, relocation, tmp_path, capfd, scale, expected):
    out = tmp_path / "result"
    code = cli.main(["relocate", str(room), "--object", "Box", "--yaw", "40", "--distance-scale", scale,
                     "--out", str(out)])
    _, stderr = capfd.readouterr()
    _assert_failed_cleanly(code, stderr, expected, out, None)
    assert not relocation.calls
