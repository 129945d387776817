"""`dimred batch` on the ground-truth scenes as a pipeline runs it: 15 jobs (removals, several
objects removed in order, relocations, alignments, one damaged .blend, one unknown object)
through the command line with two workers, killed midway and run again, then six of them (one
job of each operation, the removal of two objects in order, and both bad ones) through a Dask
scheduler with two workers started as processes. `benchmarks/bench_batch.py` runs the whole 20
jobs of `scenes.batch` (a draft removal in each of its 8 scenes where this test takes 3).

Every good job's difference image must be the single command line's, bit for bit (checked here
for one job of each kind; `benchmarks/bench_batch.py --check` checks all), the bad jobs must
fail with the single command's own error line, and the killed batch must finish without redoing
a finished job.
"""
from __future__ import annotations

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from scenes.batch import cli, single, write_jobs_file
from scenes.images import read_exr
from scenes.render import REPO
from tests.dask_processes import dask_cluster

# The draft removals of the batch: three of `scenes.batch`'s eight scenes (a grey box on a
# checker, a red box, a crate against a wall); the other jobs use the rest.
REMOVALS = ("basic_box", "red_box", "wall_contact")


def _differences(out: Path) -> dict[str, np.ndarray]:
    return {p.parent.name: read_exr(p) for p in sorted(out.glob("*/difference.exr"))}


@pytest.fixture(scope="module")
def batch(tmp_path_factory) -> dict:
    """The batch run through the command line, killed after a few jobs, then run again."""
    folder = tmp_path_factory.mktemp("batch")
    jobs_file, jobs = write_jobs_file(folder, removals=REMOVALS)
    out = folder / "local"
    # The whole process group at once: the batch, its Dask workers and the jobs in flight.
    first = subprocess.Popen([sys.executable, "-m", "addon.cli", "batch", str(jobs_file), "--out", str(out),
                              "--workers", "2"], cwd=REPO, start_new_session=True,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 600
    while len(list(out.glob("*/job.json"))) < 6 and time.monotonic() < deadline and first.poll() is None:
        time.sleep(0.1)
    os.killpg(first.pid, signal.SIGKILL)
    first.wait()
    before = {p.parent.name: p.stat().st_mtime_ns for p in out.glob("*/job.json")}
    folders = sorted(p.name for p in out.iterdir() if p.is_dir() and p.name != "logs" and not p.name.startswith("."))
    again = cli("batch", str(jobs_file), "--out", str(out), "--workers", "2")
    return {"folder": folder, "jobs": jobs, "jobs_file": jobs_file, "out": out, "before": before,
            "folders_after_kill": folders, "again": again}


@pytest.mark.slow
def test_a_killed_batch_finishes_without_redoing_finished_jobs(batch):
    before, out = batch["before"], batch["out"]
    assert 6 <= len(before) < len(batch["jobs"]) - 2, "the batch was not killed midway"
    # No half-written job folder: every one the kill left holds a whole result.
    assert batch["folders_after_kill"] == sorted(before)
    again = batch["again"]
    assert again.returncode == 2, again.stderr[-3000:]  # the damaged .blend and the unknown object
    records = json.loads((out / "summary.json").read_text())["records"]
    rows = list(csv.DictReader((out / "summary.csv").open()))
    assert [r["id"] for r in rows] == [r["id"] for r in records] == [j["id"] for j in batch["jobs"]]
    kept = {r["id"] for r in records if r["reused"]}
    assert kept == set(before)
    assert {p.parent.name: p.stat().st_mtime_ns for p in out.glob("*/job.json") if p.parent.name in before} == before
    assert {r["id"] for r in records if r["status"] != "done"} == {"damaged", "unknown-object"}
    for row in rows:
        if row["status"] == "done" and row["op"] != "align":
            assert row["width"] == "256" and float(row["peak_memory_mb"] or 1) > 0
    assert not [p for p in out.iterdir() if p.name.startswith(".")]


@pytest.mark.slow
def test_the_batchs_results_are_the_single_command_lines(batch, tmp_path):
    jobs = {j["id"]: j for j in batch["jobs"]}
    records = {r["id"]: r for r in json.loads((batch["out"] / "summary.json").read_text())["records"]}
    ids = ("basic_box-remove", "basic_box-balanced", "second_object-both", "stool-move")
    for job_id in ids:
        run = single(jobs[job_id], tmp_path / job_id)
        assert run.returncode == 0, run.stderr[-2000:]
        mine = read_exr(batch["out"] / job_id / "difference.exr")
        assert np.array_equal(mine, read_exr(tmp_path / job_id / "difference.exr")), job_id
    aligned = json.loads((batch["out"] / "basic_box-align" / "report.json").read_text())["alignment"]
    assert (batch["out"] / "basic_box-align" / "aligned.blend").is_file() and "shift_cm" in aligned
    for job_id in ("damaged", "unknown-object"):
        run = single(jobs[job_id], tmp_path / job_id)
        assert run.returncode == 2 and not (tmp_path / job_id).exists()
        assert records[job_id]["error"] == run.stderr.strip().splitlines()[-1]


# One job of each operation, two objects removed in order, and both bad ones: what the scheduler
# could change is where and in what order jobs run, the same for every kind; each job's arguments
# are the same whatever runs it (`Job.arguments`, checked on every parameter by the jobs' tests).
FARM_JOBS = ("basic_box-balanced", "second_object-both", "stool-move", "basic_box-align", "damaged", "unknown-object")


@pytest.mark.slow
def test_a_dask_scheduler_with_two_workers_gives_the_same_outputs(batch, tmp_path):
    jobs_file, farm = tmp_path / "jobs.jsonl", tmp_path / "farm"
    jobs_file.write_text("".join(json.dumps(j) + "\n" for j in batch["jobs"] if j["id"] in FARM_JOBS))
    with dask_cluster(2, tmp_path) as address:
        run = cli("batch", str(jobs_file), "--out", str(farm), "--scheduler", address)
    assert run.returncode == 2, run.stderr[-3000:]
    local, remote = _differences(batch["out"]), _differences(farm)
    assert len(remote) == 3 and remote.keys() <= local.keys()
    for job_id, image in remote.items():
        assert np.array_equal(image, local[job_id]), job_id
    statuses = [(r["id"], r["status"], r["error"]) for r in json.loads((farm / "summary.json").read_text())["records"]]
    assert statuses == [(r["id"], r["status"], r["error"])
                        for r in json.loads((batch["out"] / "summary.json").read_text())["records"]
                        if r["id"] in FARM_JOBS]
