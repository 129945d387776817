"""A whole batch with the Blender stand-in: bad jobs recorded and nothing stopped, the summary
listing every job, a re-run keeping what is finished and unchanged, a killed batch resumed, the
memory budget, and the same outputs through Dask (a local cluster and a scheduler with two
workers started as processes)."""
from __future__ import annotations

import csv
import io
import os
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from addon.batch import batch as batch_module
from addon.batch import local
from addon.batch.batch import BatchSettings, run_batch
from addon.batch.execute import Record, pending
from addon.batch.jobs import JobsFileError
from addon.batch.progress import Progress
from addon.errors import DimredError
from tests.dask_processes import dask_cluster, make_certificates
from tests.engine.batch.standin import calls, fake_launcher, summary, write_jobs

ROOT = Path(__file__).resolve().parents[3]


def _jobs(scenes: Path) -> list[dict]:
    kitchen, bedroom, hall = (str(scenes / f"{n}.blend") for n in ("kitchen", "bedroom", "hall"))
    (scenes / "damaged.blend").write_bytes(b"junk")
    return [
        {"id": "kitchen-box", "blend": kitchen, "op": "remove", "objects": ["Box", "Chair"]},
        {"id": "bedroom-move", "blend": bedroom, "op": "relocate", "object": "Box", "params": {"yaw": 30}},
        {"id": "damaged", "blend": str(scenes / "damaged.blend"), "op": "remove", "object": "Box"},
        {"id": "unknown", "blend": hall, "op": "remove", "object": "Missing"},
        {"id": "crash", "blend": hall, "op": "remove", "object": "Crash"},
        {"id": "hall-align", "blend": hall, "op": "align", "object": "Box", "params": {"quality": "draft"}},
    ]


def _settings(tmp_path: Path, launcher, **changes) -> BatchSettings:
    return BatchSettings(**{"out": str(tmp_path / "out"), "workers": 2, "launcher": launcher, "use_dask": False,
                            **changes})


def _outputs(out: Path) -> dict[str, bytes]:
    return {p.parent.name: p.read_bytes() for p in sorted(out.glob("*/difference.exr"))}


def test_bad_jobs_are_recorded_and_stop_nothing(tmp_path, scenes, fake_blender):
    jobs = write_jobs(tmp_path / "jobs.jsonl", _jobs(scenes))
    result = run_batch(str(jobs), _settings(tmp_path, fake_blender), stream=io.StringIO())
    status = {r.id: (r.status, r.error) for r in result.records}
    assert [r.id for r in result.records] == ["kitchen-box", "bedroom-move", "damaged", "unknown", "crash",
                                              "hall-align"]
    assert status["damaged"] == ("failed", "dimred: error: cannot open " + str(scenes / "damaged.blend")
                                 + ": File format is not supported")
    assert status["unknown"] == ("failed", "dimred: error: no object named 'Missing' in scene 'Scene'")
    assert status["crash"][0] == "crashed"
    assert {status[i][0] for i in ("kitchen-box", "bedroom-move", "hall-align")} == {"done"}
    assert result.failed == 3 and result.engine == "processes"
    out = tmp_path / "out"
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert [row["id"] for row in rows] == [r.id for r in result.records]
    assert rows[0]["objects"] == "Box;Chair" and rows[0]["width"] == "16" and rows[3]["error"].startswith("dimred:")
    assert summary(out)["counts"] == {"crashed": 1, "done": 3, "failed": 2}
    assert sorted(p.name for p in out.iterdir()) == ["bedroom-move", "hall-align", "kitchen-box", "logs",
                                                     "summary.csv", "summary.json"]
    # The damaged file never reached a job process: the inspection refused it.
    assert not any(str(scenes / "damaged.blend") in c and "inspect" not in c for c in calls(tmp_path))


def test_a_rerun_keeps_finished_jobs_and_redoes_what_changed(tmp_path, scenes, fake_blender, monkeypatch):
    hall = {"id": "hall", "blend": str(scenes / "hall.blend"), "op": "remove", "object": "Box"}
    jobs = write_jobs(tmp_path / "jobs.jsonl", [*_jobs(scenes)[:2], hall])
    settings = _settings(tmp_path, fake_blender)

    def runs() -> list[str]:
        """The jobs' objects and blends the stand-in ran since the last call (inspections apart)."""
        made = [c for c in calls(tmp_path) if "inspect" not in c]
        (tmp_path / "calls.jsonl").unlink(missing_ok=True)
        return sorted(Path(c[1]).stem for c in made)

    run_batch(str(jobs), settings, stream=io.StringIO())
    assert runs() == ["bedroom", "hall", "kitchen"]
    again = run_batch(str(jobs), settings, stream=io.StringIO())
    assert runs() == [] and all(r.reused and r.status == "done" for r in again.records)
    assert again.records[0].figures["width"] == 16
    (scenes / "kitchen.blend").write_bytes(b"BLENDER kitchen, edited")  # the .blend
    (scenes / "hall.blend.exr").write_bytes(b"another panorama")  # a file it reads
    run_batch(str(jobs), settings, stream=io.StringIO())
    assert runs() == ["hall", "kitchen"]
    lines = jobs.read_text().splitlines()
    write_jobs(jobs, [lines[0].replace('"objects": ["Box", "Chair"]', '"objects": ["Chair", "Box"]'), *lines[1:]])
    run_batch(str(jobs), settings, stream=io.StringIO())
    assert runs() == ["kitchen"]  # the parameters (here: the order of removal)
    monkeypatch.setattr(batch_module, "addon_version", lambda: "99.0.0")
    run_batch(str(jobs), settings, stream=io.StringIO())
    assert runs() == ["bedroom", "hall", "kitchen"]  # the add-on's version


def test_a_bad_jobs_file_runs_nothing_and_writes_nothing(tmp_path, scenes, fake_blender):
    jobs = write_jobs(tmp_path / "jobs.jsonl", [*_jobs(scenes)[:2], {"blend": "gone.blend", "op": "remove"}])
    with pytest.raises(JobsFileError, match=r"line 3: no such \.blend file"):
        run_batch(str(jobs), _settings(tmp_path, fake_blender))
    assert not (tmp_path / "out").exists() and calls(tmp_path) == []
    for bad, message in [({"workers": 0}, "--workers"), ({"timeout": -1.0}, "--timeout"),
                         ({"scheduler": "tcp://127.0.0.1:1"}, "--scheduler needs Dask")]:
        with pytest.raises(DimredError, match=message):
            run_batch(str(write_jobs(jobs, _jobs(scenes)[:1])), _settings(tmp_path, fake_blender, **bad))
        assert not (tmp_path / "out").exists()


def test_a_killed_batch_resumes_without_redoing_finished_jobs(tmp_path, scenes, monkeypatch):
    """The batch process and its children killed at once (SIGKILL to the process group, as a
    scheduler or a closed terminal does) while jobs are in flight."""
    jobs = write_jobs(tmp_path / "jobs.jsonl", [
        {"id": f"nap-{n}", "blend": str(scenes / "kitchen.blend"), "op": "remove", "object": "Nap"} for n in range(8)])
    launcher = fake_launcher(tmp_path)
    script = ("import sys; from addon.batch.batch import BatchSettings, run_batch; "
              "from addon.batch.execute import Launcher; "
              f"run_batch(sys.argv[1], BatchSettings(out=sys.argv[2], workers=2, use_dask=False, "
              f"launcher=Launcher(blender={launcher.blender!r})))")
    out = tmp_path / "out"
    monkeypatch.setenv("FAKE_DIMRED_LOG", str(tmp_path / "calls.jsonl"))
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    process = subprocess.Popen([sys.executable, "-c", script, str(jobs), str(out)], env=env,
                               start_new_session=True, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while len(list(out.glob("nap-*"))) < 3 and time.monotonic() < deadline:
        time.sleep(0.05)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    before = {p.parent.name: p.stat().st_mtime_ns for p in out.glob("nap-*/job.json")}
    assert 3 <= len(before) < 8
    # Every job folder there is whole; what was in flight is in staging folders only.
    for folder in out.glob("nap-*"):
        assert sorted(os.listdir(folder)) == ["difference.exr", "job.json", "report.json"]
    ran_before = len([c for c in calls(tmp_path) if "inspect" not in c])
    result = run_batch(str(jobs), BatchSettings(out=str(out), workers=2, use_dask=False, launcher=launcher),
                       stream=io.StringIO())
    kept = {r.id for r in result.records if r.reused}
    assert kept == set(before)
    assert all(r.status == "done" for r in result.records) and len(summary(out)["records"]) == 8
    assert {p.parent.name: p.stat().st_mtime_ns for p in out.glob("nap-*/job.json") if p.parent.name in before} \
        == before
    ran_after = len([c for c in calls(tmp_path) if "inspect" not in c]) - ran_before
    assert ran_after == 8 - len(kept)
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


def test_jobs_at_once_follow_the_memory_budget():
    """Four jobs, two workers: jobs that need 60 % of the budget run one at a time, jobs of 40 %
    two at a time, and one larger than the whole budget still runs (alone)."""

    def most_at_once(needs: list[int], budget: int | None) -> int:
        running, peak, lock = [0], [0], threading.Lock()
        tasks = [type("T", (), {"job": read_jobs_stub(n)})() for n in range(len(needs))]

        def runner(task, cancel):
            with lock:
                running[0] += 1
                peak[0] = max(peak[0], running[0])
            time.sleep(0.1)
            with lock:
                running[0] -= 1
            return pending(task.job, "done")

        ended: list[Record] = []
        local.run_local(tasks, needs, workers=2, budget=budget, on_done=ended.append, runner=runner)
        assert len(ended) == len(needs)
        return peak[0]

    assert most_at_once([60] * 4, 100) == 1
    assert most_at_once([40] * 4, 100) == 2
    assert most_at_once([10] * 4, None) == 2
    assert most_at_once([150, 10, 10], 100) == 2  # the large one alone, then the small ones together
    assert batch_module._workers(8, [3, 5], 12) == 2 and batch_module._workers(8, [3], None) == 8
    assert batch_module._workers(8, [30], 12) == 1


def read_jobs_stub(number: int):
    return type("J", (), {"id": f"job-{number}", "line": number, "op": "remove", "objects": ("Box",)})()


def test_the_progress_bar_counts_jobs_and_the_time_left():
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    stream = Terminal()
    progress = Progress(stream, total=4, workers=2)
    progress.ended(Record(id="a", line=1, op="remove", objects=("Box",), status="done", seconds=10.0))
    progress.ended(Record(id="b", line=2, op="remove", objects=("Box",), status="failed", error="x"))
    assert stream.getvalue().split("\r")[-1].strip() == "[############............] 2/4: 1 done, 1 failed, 10 s left"
    plain = io.StringIO()
    Progress(plain, total=1, workers=1).ended(Record(id="a", line=1, op="remove", objects=("Box",), status="failed",
                                                     error="dimred: error: bad"))
    assert plain.getvalue() == "dimred batch: a failed: dimred: error: bad (1/1)\n"


@pytest.mark.slow
def test_dask_gives_the_same_outputs_as_local_processes(tmp_path, scenes, fake_blender):
    """A local Dask cluster and a scheduler with two workers started as `dask` processes (as on
    a farm) run the batch to the same folders and records as local processes."""
    jobs = write_jobs(tmp_path / "jobs.jsonl", _jobs(scenes))
    local_run = run_batch(str(jobs), _settings(tmp_path, fake_blender, out=str(tmp_path / "local")),
                          stream=io.StringIO())
    dask_local = run_batch(str(jobs), _settings(tmp_path, fake_blender, out=str(tmp_path / "dask"), use_dask=True),
                           stream=io.StringIO())
    assert dask_local.engine == "dask-local"
    env = {"FAKE_DIMRED_LOG": str(tmp_path / "calls.jsonl")}
    with dask_cluster(2, tmp_path, env) as address:
        farm = run_batch(str(jobs), _settings(tmp_path, fake_blender, out=str(tmp_path / "farm"), use_dask=True,
                                              scheduler=address), stream=io.StringIO())
    assert farm.engine == "dask"

    def essentials(result):
        return [(r.id, r.status, r.error, r.figures) for r in result.records]

    assert essentials(dask_local) == essentials(local_run) == essentials(farm)
    assert _outputs(tmp_path / "local") == _outputs(tmp_path / "dask") == _outputs(tmp_path / "farm")
    assert len(_outputs(tmp_path / "farm")) == 3


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("openssl") is None, reason="openssl makes the test's certificates")
def test_a_scheduler_is_reached_over_tls_with_the_certificates(tmp_path, scenes, fake_blender):
    jobs = write_jobs(tmp_path / "jobs.jsonl", _jobs(scenes)[:2])
    certificates = tmp_path / "certificates"
    certificates.mkdir()
    tls = make_certificates(certificates)
    env = {"FAKE_DIMRED_LOG": str(tmp_path / "calls.jsonl")}
    with dask_cluster(2, tmp_path, env, tls=tls) as address:
        assert address.startswith("tls://")
        with pytest.raises(DimredError, match="needs --tls-ca-file"):
            run_batch(str(jobs), _settings(tmp_path, fake_blender, use_dask=True, scheduler=address))
        farm = run_batch(str(jobs), _settings(tmp_path, fake_blender, use_dask=True, scheduler=address, tls=tls),
                         stream=io.StringIO())
    assert farm.engine == "dask" and [r.status for r in farm.records] == ["done", "done"]


@pytest.mark.slow
def test_workers_without_the_project_are_refused_at_once(tmp_path, scenes, fake_blender):
    """A farm node started without the checkout on its Python path could not unpickle a job:
    the batch says so before it submits anything, instead of waiting for ever."""
    jobs = write_jobs(tmp_path / "jobs.jsonl", _jobs(scenes)[:1])
    with dask_cluster(1, tmp_path, project_on_path=False) as address:
        started = time.monotonic()
        with pytest.raises(DimredError, match=r"workers cannot import addon\.batch\.execute"):
            run_batch(str(jobs), _settings(tmp_path, fake_blender, use_dask=True, scheduler=address),
                      stream=io.StringIO())
    assert time.monotonic() - started < 60
    assert all("inspect" in c for c in calls(tmp_path))  # no job was run
