"""The command line's `remove` of several objects in order, `inspect`, and `batch` through both
entry points (`python -m addon.cli` and `blender -c dimred`, in-process here), with a stand-in
engine where the composition is what is checked."""
from __future__ import annotations

import json
import os
import subprocess
import sys

import bpy
import numpy as np
import pytest

from addon import pipeline
from addon.blender import cli
from addon.io.exr import read_exr
from addon.radiance import round_to_stored_precision
from tests.blender.test_cli import HDRI, ROOT, FakeEngine, _lines, _plane, _save_scene

pytestmark = pytest.mark.usefixtures("fresh_blender")


@pytest.fixture
def room(tmp_path):
    """The command line tests' room: floor, box, lamp, camera, lit by HDRI, saved as room.blend."""
    return _save_scene(tmp_path)


def _stand_in_engine(monkeypatch) -> FakeEngine:
    fake = FakeEngine()
    monkeypatch.setattr(pipeline, "remove_object", fake)
    return fake


def test_several_objects_are_removed_in_order_each_from_what_the_ones_before_left(room, monkeypatch, tmp_path,
                                                                                  capfd):
    engine = _stand_in_engine(monkeypatch)
    bpy.ops.wm.open_mainfile(filepath=str(room))
    _plane("Rug", 0.8, 0.01)
    bpy.ops.wm.save_mainfile()
    capfd.readouterr()
    out = tmp_path / "result"
    assert cli.main(["remove", str(room), "--object", "Box", "--object", "Rug", "--out", str(out)]) == 0
    stdout, _ = capfd.readouterr()
    assert _lines(stdout)[0].startswith("dimred: removed 'Box', 'Rug' in ")
    first, second = engine.calls
    assert (first["object"], second["object"]) == ("Box", "Rug")
    np.testing.assert_array_equal(first["scene"].hdri, HDRI)
    # The second removal sees the panorama with the first one's difference added and the room
    # without the first object, as the panel's second removal does.
    np.testing.assert_array_equal(second["scene"].hdri, HDRI + np.float32(0.25))
    assert "Box" in first["scene"].object_names and "Box" not in second["scene"].object_names
    np.testing.assert_array_equal(read_exr(out / "difference.exr"), np.full_like(HDRI, 0.5))
    np.testing.assert_array_equal(read_exr(out / "edited.exr"), round_to_stored_precision(HDRI + np.float32(0.5)))
    report = json.loads((out / "report.json").read_text())
    assert report["objects"] == ["Box", "Rug"] and len(report["removals"]) == 2
    assert report["seconds"]["synthesis"] == 0.02 and report["hidden_pixels"] == 0
    assert report["warnings"] == ["Box: 3 pixels clamped", "Rug: 3 pixels clamped"]


@pytest.mark.parametrize("arguments, expected", [
    (["--object", "Box", "--object", "Box"], "an --object is named twice"),
    (["--object", "Box", "--object", "Chair"], "no object named 'Chair'"),
])
def test_several_objects_are_checked_before_any_work(room, monkeypatch, tmp_path, capfd, arguments, expected):
    engine = _stand_in_engine(monkeypatch)
    out = tmp_path / "result"
    assert cli.main(["remove", str(room), *arguments, "--out", str(out)]) == 2
    assert expected in capfd.readouterr().err and not engine.calls and not out.exists()


def test_relocate_and_align_take_one_object(room, tmp_path, capfd):
    for command in (["relocate", "--yaw", "10"], ["align"]):
        out = tmp_path / command[0]
        arguments = [command[0], str(room), "--object", "Box", "--object", "Floor", *command[1:], "--out", str(out)]
        code = cli.main(arguments)
        assert code == 2 and f"{command[0]} takes one --object, not 2" in capfd.readouterr().err


def test_inspect_prints_each_scenes_panorama_size_and_file(room, tmp_path, capfd):
    garbage = tmp_path / "garbage.blend"
    garbage.write_bytes(b"BLENDER? no" * 50)
    assert cli.main(["inspect", str(room), str(garbage)]) == 0
    first, second = (json.loads(line) for line in _lines(capfd.readouterr().out))
    assert first == {"blend": str(room), "size": [16, 8], "files": [str(tmp_path / "probe.exr")]}
    assert second["blend"] == str(garbage) and second["error"].startswith("cannot open")


def _jobs_file(tmp_path, room) -> str:
    path = tmp_path / "jobs.jsonl"
    path.write_text(json.dumps({"id": "one", "blend": str(room), "op": "remove", "object": "Box"}) + "\n"
                    + json.dumps({"id": "two", "blend": str(room), "op": "remove", "object": "Chair"}) + "\n",
                    encoding="utf-8")
    return str(path)


def test_batch_through_the_blender_command_runs_local_processes(room, tmp_path, capfd):
    """`blender -c dimred batch`: the jobs' children are the real command line (here the bpy
    module's `python -m addon.cli`, the tiny room's real removal), never Dask."""
    out = tmp_path / "out"
    code = cli.blender_command(["batch", _jobs_file(tmp_path, room), "--out", str(out), "--workers", "1"])
    stdout, stderr = capfd.readouterr()
    assert code == 1, stderr
    assert "batch of 2 jobs: 1 done (0 kept from an earlier run), 1 failed" in stdout
    summary = json.loads((out / "summary.json").read_text())
    assert [(r["id"], r["status"]) for r in summary["records"]] == [("one", "done"), ("two", "failed")]
    assert summary["records"][1]["error"] == "dimred: error: no object named 'Chair' in scene 'Scene'"
    assert read_exr(out / "one" / "difference.exr").shape == HDRI.shape
    assert "dimred batch: two failed: dimred: error: no object named 'Chair'" in stderr


def test_batch_with_a_bad_jobs_line_reports_it_and_runs_nothing(room, tmp_path, capfd):
    path = tmp_path / "jobs.jsonl"
    path.write_text(json.dumps({"blend": str(room), "op": "remove", "object": "Box"}) + "\n"
                    + json.dumps({"blend": str(room), "op": "erase", "object": "Box"}) + "\n"
                    + json.dumps({"blend": str(room), "op": "remove"}) + "\n", encoding="utf-8")
    out = tmp_path / "out"
    assert cli.main(["batch", str(path), "--out", str(out)]) == 2
    stderr = _lines(capfd.readouterr().err)
    assert stderr[0].endswith("jobs.jsonl line 2: 'op' must be one of remove, relocate, align, not 'erase'")
    assert stderr[1].endswith("jobs.jsonl line 3: missing field 'object' (the object's name)")
    assert stderr[2] == "dimred: error: 2 bad job line(s); no job was run"
    assert not out.exists()


@pytest.mark.parametrize("arguments, expected", [
    (["--tls-cert", "c.pem"], "TLS needs all three"),
    (["--scheduler", "ftp://farm:8786"], "give tcp://HOST:PORT or tls://HOST:PORT"),
    (["--scheduler", "tls://farm:8786"], "a tls:// scheduler needs --tls-ca-file"),
])
def test_batch_refuses_a_scheduler_it_cannot_reach_safely(room, tmp_path, capfd, arguments, expected):
    code = cli.main(["batch", _jobs_file(tmp_path, room), "--out", str(tmp_path / "out"), *arguments])
    assert code == 2 and expected in capfd.readouterr().err


def test_batch_module_entry_point(room, tmp_path):
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, "-m", "addon.cli", "batch", _jobs_file(tmp_path, room), "--out", str(out),
                           "--workers", "1"], cwd=ROOT, capture_output=True, text=True, timeout=300,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert proc.returncode == 1, proc.stderr[-2000:]
    assert json.loads((out / "summary.json").read_text())["counts"] == {"done": 1, "failed": 1}
