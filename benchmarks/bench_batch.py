"""The batch of 20 ground-truth jobs (`scenes.batch`) through each engine: wall seconds, jobs a
minute, the largest job's peak memory and the batch process's own, and a re-run's seconds.

    .venv/bin/python benchmarks/bench_batch.py [--workers 2] [--check]

Prints a table and writes it into docs/results/bench_batch.md.

Rows, each a fresh batch process measured from outside (its rusage): local processes (what
`blender -c dimred batch` runs), a local Dask cluster (`python -m addon.cli batch`), the same
batch run again into the Dask run's folder (every finished job kept: the cost of resuming), and
one job after another (`--workers 1`, local processes), the base of the speed-up column. With
--check, every good job's difference image is compared with the single command line's (16
single runs more). The renders are the ground-truth cache's (rendered when missing). Timings on
a shared machine are noisy: compare the rows of one run.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from results import Table, write
from scenes.batch import single, write_jobs_file
from scenes.images import read_exr
from scenes.render import REPO

COLUMNS = ("engine", "workers", "seconds", "jobs/min", "speed-up", "done", "kept", "failed",
           "largest job GB", "batch process GB")

# The batch process reports its own peak: its rusage seen from outside would include its jobs'.
_RUN = """
import resource, sys
from addon.batch.batch import BatchSettings, run_batch
result = run_batch(sys.argv[1], BatchSettings(out=sys.argv[2], workers=int(sys.argv[3]),
                                              use_dask=sys.argv[4] == "dask"))
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
"""


def _batch(jobs: Path, out: Path, workers: int, engine: str) -> dict:
    """One batch in a fresh process: wall seconds, its peak memory and the summary's counts."""
    started = time.perf_counter()
    run = subprocess.run([sys.executable, "-c", _RUN, str(jobs), str(out), str(workers), engine], cwd=REPO,
                         env={**os.environ, "PYTHONPATH": str(REPO)}, stderr=subprocess.DEVNULL, stdout=subprocess.PIPE,
                         text=True)
    seconds = time.perf_counter() - started
    if run.returncode != 0:
        raise SystemExit(f"bench_batch: the {engine} batch failed")
    records = json.loads((out / "summary.json").read_text())["records"]
    peaks = [r["peak_memory_mb"] for r in records if r["peak_memory_mb"] and not r["reused"]]
    return {"seconds": seconds, "done": sum(r["status"] == "done" for r in records),
            "kept": sum(r["reused"] for r in records), "failed": sum(r["status"] != "done" for r in records),
            "largest": max(peaks) / 1e3 if peaks else None, "own": int(run.stdout.split()[-1]) / 1e9}


def _check(jobs: list[dict], out: Path, folder: Path) -> tuple[int, list[str]]:
    """How many good jobs' difference images equal the single command line's; the ones that differ."""
    same, differ = 0, []
    for job in jobs:
        result = out / job["id"] / "difference.exr"
        if not result.exists():
            continue
        run = single(job, folder / job["id"])
        if run.returncode == 0 and np.array_equal(read_exr(result), read_exr(folder / job["id"] / "difference.exr")):
            same += 1
        else:
            differ.append(job["id"])
    return same, differ


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--check", action="store_true", help="compare every good job with the single command line")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="bench_batch-") as scratch:
        folder = Path(scratch)
        jobs_file, jobs = write_jobs_file(folder)
        rows = [("processes", 1, _batch(jobs_file, folder / "serial", 1, "processes")),
                ("processes", args.workers, _batch(jobs_file, folder / "processes", args.workers, "processes")),
                ("dask-local", args.workers, _batch(jobs_file, folder / "dask", args.workers, "dask")),
                ("dask-local, re-run", args.workers, _batch(jobs_file, folder / "dask", args.workers, "dask"))]
        base = rows[0][2]["seconds"]
        table = Table(COLUMNS, title=f"{len(jobs)} jobs of the batch test (scenes/batch.py)")
        for engine, workers, r in rows:
            table.row(engine, workers, f"{r['seconds']:.1f}", f"{60 * len(jobs) / r['seconds']:.1f}",
                      f"{base / r['seconds']:.2f}", r["done"], r["kept"], r["failed"],
                      "" if r["largest"] is None else f"{r['largest']:.2f}", f"{r['own']:.2f}")
        notes = []
        if args.check:
            same, differ = _check(jobs, folder / "dask", folder / "single")
            notes.append(f"{same} good jobs' difference images equal the single command line's"
                         + (f"; differ: {', '.join(differ)}" if differ else ""))
        write(table, notes=notes)

if __name__ == "__main__":
    main()
