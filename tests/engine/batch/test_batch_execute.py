"""One job in its own process: its folder appears whole or not at all, a failure, crash or
timeout is a record with its one-line error, and the child's peak memory is measured."""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import pytest

import addon
from addon.batch.execute import MANIFEST, Launcher, Task, finished, remove_leftovers, run_job
from addon.batch.inspection import inspect_scenes
from addon.batch.jobs import read_jobs
from tests.engine.batch.standin import write_jobs


def _task(tmp_path, scenes, launcher, name="Box", timeout=None, **fields) -> Task:
    job = {"id": f"job-{name.lower()}", "blend": str(scenes / "kitchen.blend"), "op": "remove", "object": name,
           **fields}
    [parsed] = read_jobs(str(write_jobs(tmp_path / "jobs.jsonl", [job])))
    return Task(job=parsed, out=str(tmp_path / "out"), fingerprint="f" * 64,
                inputs={parsed.blend: "d" * 64}, launcher=launcher, timeout=timeout)


def test_a_job_that_succeeds_gets_its_whole_folder_and_manifest(tmp_path, scenes, fake_blender):
    task = _task(tmp_path, scenes, fake_blender, params={"quality": "draft"})
    record = run_job(task)
    assert record.status == "done" and not record.error and record.seconds > 0
    folder = tmp_path / "out" / "job-box"
    assert sorted(os.listdir(folder)) == ["difference.exr", MANIFEST, "report.json"]
    assert (folder / "difference.exr").read_bytes().startswith(b"BLENDER kitchen")
    manifest = json.loads((folder / MANIFEST).read_text())
    assert manifest["fingerprint"] == task.fingerprint and manifest["inputs"] == task.inputs
    assert manifest["files"] == ["difference.exr", "report.json"]
    assert record.figures == {"width": 16, "height": 8, "engine_seconds": 0.01, "hidden_pixels": 5, "warnings": 1}
    assert finished(task.job, task.out) == manifest
    # The child's command line, as the log keeps it, is the one a user would type.
    log = (tmp_path / "out" / "logs" / "job-box.log").read_text()
    assert f"-b {task.job.blend} -c dimred remove --object Box --out" in log and "--quality draft" in log
    # No staging folder is left behind.
    assert sorted(os.listdir(tmp_path / "out")) == ["job-box", "logs"]


def test_a_rerun_replaces_the_folder_whole(tmp_path, scenes, fake_blender):
    task = _task(tmp_path, scenes, fake_blender)
    run_job(task)
    (tmp_path / "out" / "job-box" / "stale.txt").write_text("from an older run")
    assert finished(task.job, task.out) is not None
    (scenes / "kitchen.blend").write_bytes(b"BLENDER kitchen, edited")
    assert run_job(task).status == "done"
    folder = tmp_path / "out" / "job-box"
    assert not (folder / "stale.txt").exists()
    assert (folder / "difference.exr").read_bytes().startswith(b"BLENDER kitchen, edited")


@pytest.mark.parametrize("name, status, error", [
    ("Missing", "failed", "dimred: error: no object named 'Missing' in scene 'Scene'"),
    ("Crash", "crashed", "the job's process was killed by signal SIGKILL"),
    ("Slow", "timeout", "ran past the timeout of 1.5 s and was stopped"),
])
def test_a_job_that_fails_leaves_no_folder_and_says_why_in_one_line(tmp_path, scenes, fake_blender, name, status,
                                                                     error):
    task = _task(tmp_path, scenes, fake_blender, name=name, timeout=1.5)
    record = run_job(task)
    assert (record.status, record.error) == (status, error)
    assert record.seconds < 30
    assert sorted(os.listdir(tmp_path / "out")) == ["logs"]
    assert finished(task.job, task.out) is None


@pytest.mark.skipif(not hasattr(os, "wait4"), reason="the system reports no child's resource use")
def test_the_childs_peak_memory_is_measured(tmp_path, scenes, fake_blender):
    small = run_job(_task(tmp_path, scenes, fake_blender))
    large = run_job(_task(tmp_path, scenes, fake_blender, name="Hog"))
    # Not the test process's own memory (bpy's hundreds of MB, held by the child until it execs).
    assert small.peak_memory_mb is None or small.peak_memory_mb < 100
    assert 200 <= large.peak_memory_mb < 400


def test_an_incomplete_folder_is_not_taken_for_a_finished_job(tmp_path, scenes, fake_blender):
    task = _task(tmp_path, scenes, fake_blender)
    run_job(task)
    (tmp_path / "out" / "job-box" / "difference.exr").unlink()
    assert finished(task.job, task.out) is None
    (tmp_path / "out" / "job-box" / MANIFEST).write_text("{ half written")
    assert finished(task.job, task.out) is None


def test_leftovers_of_a_killed_batch_are_removed(tmp_path):
    out = tmp_path / "out"
    for name in (".partial-job-1a2b3c4d", ".old-job-5e6f7a8b", "job", "logs"):
        (out / name).mkdir(parents=True)
    remove_leftovers(str(out))
    assert sorted(os.listdir(out)) == ["job", "logs"]


def test_inspection_survives_a_scene_that_kills_blender(tmp_path, scenes, fake_blender):
    for name in ("crash", "damaged"):
        (scenes / f"{name}.blend").write_bytes(b"junk")
    blends = [str(scenes / f"{name}.blend") for name in ("bedroom", "crash", "damaged", "hall", "kitchen")]
    found = inspect_scenes(blends, fake_blender)
    assert set(found) == set(blends)
    assert found[blends[0]].size == (16, 8) and found[blends[0]].files == (blends[0] + ".exr",)
    assert "process ended while opening it" in found[blends[1]].error
    assert "File format is not supported" in found[blends[2]].error
    assert not found[blends[3]].error and not found[blends[4]].error


def test_the_python_launcher_runs_this_checkouts_command_line(tmp_path, scenes):
    task = _task(tmp_path, scenes, launcher=Launcher())
    command, env = task.launcher.command(task.job, "/out")
    assert command[:5] == [sys.executable, "-m", "addon.cli", "remove", task.job.blend]
    assert env["PYTHONPATH"].split(os.pathsep)[0] == str(Path(addon.__file__).resolve().parents[1])
