"""A whole batch: check the jobs file, keep what an earlier run finished, inspect the scenes
still to run, run them (Dask or local processes) and keep the summary current.

Order of work: the jobs file is checked whole first (a bad line stops the batch before anything
is written); jobs whose folder holds a finished result with an unchanged fingerprint are kept;
the .blend files of the others are inspected in one child process (the panorama's size gives
each job's memory reservation, the files it reads go into its fingerprint); then the jobs run.
"""
from __future__ import annotations

import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TextIO

from .. import memory
from ..errors import DimredError
from ..quality import DEFAULT_QUALITY
from . import cluster, execute
from .execute import Launcher, Record, Task
from .fingerprint import addon_version, file_digest, job_fingerprint
from .inspection import Inspection, inspect_scenes
from .jobs import Job, read_jobs
from .local import run_local
from .progress import Progress
from .summary import write_summary


@dataclass(frozen=True)
class BatchSettings:
    out: str
    workers: int
    scheduler: str | None = None  # a Dask scheduler's address; None: this machine
    timeout: float | None = None  # seconds per job
    tls: cluster.TLSFiles | None = None
    launcher: Launcher = field(default_factory=Launcher)
    use_dask: bool = True  # False: local processes even where Dask is installed (inside Blender)


@dataclass(frozen=True)
class BatchResult:
    records: tuple[Record, ...]
    engine: str  # what ran the jobs: "dask-local", "dask", "processes" or "none"
    workers: int  # jobs at most at once on this machine (None-like 0 for a remote cluster)

    @property
    def failed(self) -> int:
        return sum(r.status != "done" for r in self.records)


def run_batch(jobs_file: str, settings: BatchSettings, *, stream: TextIO | None = None,
              inspect: Callable[[Sequence[str], Launcher], dict[str, Inspection]] = inspect_scenes,
              available: Callable[[], int | None] = memory.available_bytes) -> BatchResult:
    """Run every job of `jobs_file` into `settings.out`; DimredError (nothing written) when the
    jobs file or the settings are bad."""
    stream = sys.stderr if stream is None else stream
    jobs = read_jobs(jobs_file)
    if settings.workers < 1:
        raise DimredError(f"--workers must be at least 1, not {settings.workers}")
    if settings.timeout is not None and settings.timeout <= 0:
        raise DimredError(f"--timeout must be positive, not {settings.timeout:g}")
    out = os.path.abspath(settings.out)
    if os.path.exists(out) and not os.path.isdir(out):
        raise DimredError(f"--out {out} is a file, not a folder")
    dask = settings.use_dask and (settings.scheduler is not None or cluster.dask_available())
    if settings.scheduler is not None and not settings.use_dask:
        raise DimredError("--scheduler needs Dask, which Blender's Python does not have: run "
                          "`python -m addon.cli batch` from the project's environment")
    if settings.scheduler is not None:
        cluster.check_address(settings.scheduler, settings.tls,
                              warn=lambda message: print(f"dimred: warning: {message}", file=stream))
    os.makedirs(out, exist_ok=True)
    execute.remove_leftovers(out)
    started = time.time()
    digests: dict[str, str] = {}
    records: dict[str, Record] = {job.id: execute.pending(job) for job in jobs}
    for job in jobs:
        kept = _kept(job, out, digests)
        if kept is not None:
            records[job.id] = kept
    to_run = [job for job in jobs if records[job.id].status == "pending"]
    meta = {"jobs_file": os.path.abspath(jobs_file), "version": addon_version(), "started": started}

    def save() -> None:
        write_summary(out, [records[job.id] for job in jobs], meta={**meta, "seconds": round(time.time() - started, 2)})

    tasks, needs = [], []
    if to_run:
        inspections = inspect(sorted({job.blend for job in to_run}), settings.launcher)
        for job in to_run:
            inspection = inspections[job.blend]
            if inspection.error:
                records[job.id] = execute.pending(job, "failed", f"dimred: error: {inspection.error}")
                continue
            task, need = _task(job, inspection, out, digests, settings)
            tasks.append(task)
            needs.append(need)
    budget = available()
    workers = _workers(settings.workers, needs, budget)
    engine = "processes"
    if not tasks:
        engine = "none"
    elif dask:
        engine = "dask" if settings.scheduler else "dask-local"
    progress = Progress(stream, total=len(jobs), workers=workers)
    for job in jobs:
        if records[job.id].status != "pending":
            progress.ended(records[job.id])
    save()

    def done(record: Record) -> None:
        records[record.id] = record
        progress.ended(record)
        save()

    try:
        if tasks and dask:
            cluster.run_dask(tasks, needs, scheduler=settings.scheduler, workers=workers, tls=settings.tls,
                             on_done=done)
        elif tasks:
            run_local(tasks, needs, workers=workers, budget=budget, on_done=done)
    finally:
        progress.close()
        save()
    return BatchResult(records=tuple(records[job.id] for job in jobs), engine=engine,
                       workers=0 if settings.scheduler else workers)


def _kept(job: Job, out: str, digests: dict[str, str]) -> Record | None:
    """The record of an earlier run of `job` to keep: finished, and nothing it depends on changed."""
    manifest = execute.finished(job, out)
    if manifest is None:
        return None
    try:
        inputs = {path: _digest(path, digests) for path in manifest["inputs"]}
    except OSError:
        return None
    if job.blend not in inputs:
        return None
    if job_fingerprint(job, inputs, version=addon_version()) != manifest.get("fingerprint"):
        return None
    return execute.reused(job, manifest)


def _task(job: Job, inspection: Inspection, out: str, digests: dict[str, str], settings: BatchSettings
          ) -> tuple[Task, int]:
    params = job.parameters()
    files = [job.blend, *inspection.files] + ([params["mask"]] if "mask" in params else [])
    inputs = {path: _digest(path, digests) for path in dict.fromkeys(files)}
    fingerprint = job_fingerprint(job, inputs, version=addon_version())
    width, height = inspection.size
    need = memory.required_bytes(width, height, quality=params.get("quality", DEFAULT_QUALITY),
                                 working_width=params.get("working_width"))
    return Task(job=job, out=out, fingerprint=fingerprint, inputs=inputs, launcher=settings.launcher,
                timeout=settings.timeout), need


def _digest(path: str, digests: dict[str, str]) -> str:
    if path not in digests:
        digests[path] = file_digest(path)
    return digests[path]


def _workers(requested: int, needs: Sequence[int], budget: int | None) -> int:
    """Jobs at once on this machine: the request, fewer when the largest job's memory times the
    count would not fit the memory free now (at least one)."""
    if not needs or budget is None:
        return requested
    return max(1, min(requested, budget // max(needs)))
