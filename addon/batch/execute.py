"""One job of a batch, run in a child process: the same command a user types, its files written
into a hidden staging folder and renamed to the job's folder only when the run succeeded.

`run_job` is what every scheduler calls (a local thread or a Dask worker, on this machine or on
a farm node): it takes and returns plain picklable data. A job that fails, crashes or runs past
its timeout becomes a record with its one-line error; nothing of it is left in the output
folder but its log.
"""
from __future__ import annotations

import contextlib
import json
import os
import secrets
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass, field

from .jobs import Job

#: The file in each job's folder that says what the job was and what it gave.
MANIFEST = "job.json"
LOGS = "logs"
_POLL_SECONDS = 0.05


@dataclass(frozen=True)
class Launcher:
    """How a job's child process starts: `python -m addon.cli` (the development environment,
    resolved on the machine that runs the job) or a Blender executable with the extension
    enabled (`blender -b FILE -c dimred ...`)."""

    blender: str = ""  # the Blender executable; "" for the Python module

    def command(self, job: Job, out: str) -> tuple[list[str], dict[str, str]]:
        """The child's argument list and environment for `job` writing into `out`."""
        arguments = job.arguments(out)
        if self.blender:
            return [self.blender, "-b", job.blend, "-c", "dimred", *arguments], dict(os.environ)
        command, env = self.python_command()
        return [*command, arguments[0], job.blend, *arguments[1:]], env

    def inspect_command(self, blends: Sequence[str]) -> tuple[list[str], dict[str, str]]:
        """The child's argument list and environment for `dimred inspect BLEND...`."""
        if self.blender:
            return [self.blender, "-b", "-c", "dimred", "inspect", *blends], dict(os.environ)
        command, env = self.python_command()
        return [*command, "inspect", *blends], env

    @staticmethod
    def python_command() -> tuple[list[str], dict[str, str]]:
        """`python -m addon.cli` of this interpreter with the folder holding the engine's package
        on its path (a checkout, or an installed extension, where the package sits below
        `bl_ext.<repository>`: the engine imports nothing outside it), and its environment."""
        env = dict(os.environ)
        package = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        root = os.path.dirname(package)
        env["PYTHONPATH"] = os.pathsep.join(p for p in (root, env.get("PYTHONPATH", "")) if p)
        return [sys.executable, "-m", f"{os.path.basename(package)}.cli"], env


@dataclass(frozen=True)
class Task:
    """A job as a scheduler hands it to `run_job`."""

    job: Job
    out: str  # the batch's output folder (the job's folder is out/<id>)
    fingerprint: str
    inputs: dict[str, str]  # path -> sha256 of every file the job reads, the .blend first
    launcher: Launcher = field(default_factory=Launcher)
    timeout: float | None = None  # seconds


@dataclass(frozen=True)
class Record:
    """What the batch's summary says about one job."""

    id: str
    line: int
    op: str
    objects: tuple[str, ...]
    status: str  # done, failed, timeout, crashed (killed by a signal), cancelled (Ctrl-C) or pending
    reused: bool = False  # finished by an earlier run of the batch, its inputs unchanged
    seconds: float | None = None
    peak_memory_mb: float | None = None
    figures: dict = field(default_factory=dict)  # the report's main figures
    error: str = ""

    def as_dict(self) -> dict:
        return asdict(self)


def pending(job: Job, status: str = "pending", error: str = "") -> Record:
    return Record(id=job.id, line=job.line, op=job.op, objects=job.objects, status=status, error=error)


def run_job(task: Task, cancel: threading.Event | None = None) -> Record:
    """Run `task` in a child process and install its folder out/<id> when it succeeds."""
    job = task.job
    logs = os.path.join(task.out, LOGS)
    os.makedirs(logs, exist_ok=True)
    staging = os.path.join(task.out, f".partial-{job.id}-{secrets.token_hex(4)}")
    os.makedirs(staging)
    try:
        command, env = task.launcher.command(job, staging)
        with open(os.path.join(logs, f"{job.id}.log"), "w+b") as log:
            log.write(("$ " + subprocess.list2cmdline(command) + "\n").encode())
            log.flush()
            started = time.perf_counter()
            status, returncode, peak = _run_child(command, env, log, task.timeout, cancel)
            seconds = round(time.perf_counter() - started, 3)
            log.seek(0)
            output = log.read().decode("utf-8", "replace")
        record = Record(id=job.id, line=job.line, op=job.op, objects=job.objects, status=status, seconds=seconds,
                        peak_memory_mb=peak)
        if status == "done" and returncode == 0:
            record = _install(task, staging, record)
        else:
            record = _failed(record, status, returncode, output, task.timeout)
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return record


def _run_child(command: list[str], env: dict[str, str], log, timeout: float | None,
               cancel: threading.Event | None) -> tuple[str, int, float | None]:
    """(status, return code, peak resident memory in MB) of the child, killed at `timeout`
    or when `cancel` is set."""
    process = subprocess.Popen(command, env=env, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT)
    deadline = None if timeout is None else time.monotonic() + timeout
    status, high_water = "done", None
    arguments = "\0".join(command[1:]).encode()
    while True:
        returncode, usage_peak = _reap(process)
        if returncode is not None:
            on_linux = os.path.isdir("/proc/self")
            return status, returncode, high_water if on_linux else usage_peak
        high_water = _high_water(process.pid, arguments, high_water)
        if status == "done" and cancel is not None and cancel.is_set():
            status = "cancelled"
            process.kill()
        elif status == "done" and deadline is not None and time.monotonic() > deadline:
            status = "timeout"
            process.kill()
        time.sleep(_POLL_SECONDS)


def _high_water(pid: int, arguments: bytes, so_far: float | None) -> float | None:
    """The child's peak resident memory in MB as Linux keeps it for the program it runs
    (VmHWM), once it runs it (its command line ends with `arguments`, whatever interpreter a
    script's #! line put before them). A child's rusage would count the
    batch process's own memory too, which the child holds between fork and exec; a child that
    ends before its first reading has no figure (None) rather than that one."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as handle:
            if not handle.read().rstrip(b"\0").endswith(arguments):
                return so_far
        with open(f"/proc/{pid}/status", encoding="ascii") as lines:
            for line in lines:
                if line.startswith("VmHWM:"):
                    megabytes = round(int(line.split()[1]) * 1024 / 1e6, 1)
                    return megabytes if so_far is None else max(so_far, megabytes)
    except (OSError, ValueError, IndexError):
        pass
    return so_far


def _reap(process: subprocess.Popen) -> tuple[int | None, float | None]:
    """(return code, peak memory in MB) once the child has exited, else (None, None). The peak
    is the child's rusage (wait4), where the system reports one; `_run_child` prefers /proc's."""
    if not hasattr(os, "wait4"):
        return process.poll(), None
    pid, status, usage = os.wait4(process.pid, os.WNOHANG)
    if pid == 0:
        return None, None
    process.returncode = os.waitstatus_to_exitcode(status)
    # ru_maxrss is in kilobytes on Linux, in bytes on macOS.
    scale = 1.0 if sys.platform == "darwin" else 1024.0
    return process.returncode, round(usage.ru_maxrss * scale / 1e6, 1)


def _failed(record: Record, status: str, returncode: int, output: str, timeout: float | None) -> Record:
    if status == "timeout":
        return _with(record, status="timeout", error=f"ran past the timeout of {timeout:g} s and was stopped")
    if status == "cancelled":
        return _with(record, status="cancelled", error="cancelled with the batch")
    if returncode < 0:
        name = signal.Signals(-returncode).name if -returncode in signal.valid_signals() else str(-returncode)
        return _with(record, status="crashed", error=f"the job's process was killed by signal {name}")
    return _with(record, status="failed", error=_error_line(output, returncode))


def _error_line(output: str, returncode: int) -> str:
    """The command's own one-line error (`dimred: error: ...`, or its last `dimred:` line), else
    the output's last line."""
    lines = [line.strip() for line in output.splitlines() if line.strip()]
    for prefix in ("dimred: error:", "dimred:"):
        found = [line for line in lines if line.startswith(prefix)]
        if found:
            return found[-1]
    tail = lines[-1] if len(lines) > 1 else ""
    return f"exit status {returncode}" + (f": {tail}" if tail else "")


def _with(record: Record, **changes) -> Record:
    return Record(**{**record.as_dict(), **changes})


def _install(task: Task, staging: str, record: Record) -> Record:
    """Write the manifest into the staging folder and rename it to out/<id>, replacing an
    earlier folder: at every moment out/<id> is either a whole result or absent."""
    record = _with(record, figures=_figures(staging))
    files = sorted(name for name in os.listdir(staging))
    manifest = {"record": record.as_dict(), "fingerprint": task.fingerprint, "inputs": task.inputs,
                "job": {"blend": task.job.blend, "op": task.job.op, "objects": list(task.job.objects),
                        "params": task.job.parameters()},
                "files": files}
    with open(os.path.join(staging, MANIFEST), "w", encoding="utf-8") as handle:
        json.dump(manifest, handle, indent=2)
    final = os.path.join(task.out, task.job.id)
    old = None
    if os.path.exists(final):
        old = os.path.join(task.out, f".old-{task.job.id}-{secrets.token_hex(4)}")
        os.replace(final, old)
    os.replace(staging, final)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
    return record


def finished(job: Job, out: str) -> dict | None:
    """The manifest of a finished earlier run of `job` whose files are all there, else None."""
    folder = os.path.join(out, job.id)
    try:
        with open(os.path.join(folder, MANIFEST), encoding="utf-8") as handle:
            manifest = json.load(handle)
        if manifest["record"]["status"] != "done":
            return None
        if not all(os.path.isfile(os.path.join(folder, name)) for name in manifest["files"]):
            return None
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return manifest


def reused(job: Job, manifest: dict) -> Record:
    """The summary's record of a job kept from an earlier run."""
    earlier = manifest["record"]
    return Record(id=job.id, line=job.line, op=job.op, objects=job.objects, status="done", reused=True,
                  seconds=earlier.get("seconds"), peak_memory_mb=earlier.get("peak_memory_mb"),
                  figures=dict(earlier.get("figures", {})))


def remove_leftovers(out: str) -> None:
    """Staging folders of jobs that were in flight when a batch was killed."""
    with contextlib.suppress(FileNotFoundError):
        for name in os.listdir(out):
            if name.startswith((".partial-", ".old-")):
                shutil.rmtree(os.path.join(out, name), ignore_errors=True)


def _figures(folder: str) -> dict:
    """The report's main figures: size, engine seconds, fill, warnings, and the move's or the
    alignment's result where there is one."""
    try:
        with open(os.path.join(folder, "report.json"), encoding="utf-8") as handle:
            report = json.load(handle)
    except (OSError, ValueError):
        return {}
    figures = {}
    if "image_size" in report:
        figures["width"], figures["height"] = report["image_size"]
    total = report.get("seconds", {}).get("total")
    if total is not None:
        figures["engine_seconds"] = total
    for key in ("hidden_pixels", "hidden_region_filled", "bounces"):
        if key in report:
            figures[key] = report[key]
    if "warnings" in report:
        figures["warnings"] = len(report["warnings"])
    relocation = report.get("relocation") or {}
    if "elevation_change" in relocation:
        figures["elevation_change_deg"] = relocation["elevation_change"]
    alignment = report.get("alignment") or {}
    for key in ("shift_cm", "turn_deg", "scale_percent"):
        if key in alignment:
            figures[f"alignment_{key}"] = alignment[key]
    return figures
