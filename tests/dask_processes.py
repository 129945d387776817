"""A real Dask cluster as a farm runs it: `dask scheduler` and `dask worker` processes started
from the command line on localhost, the workers with this checkout on their Python path."""
from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


@contextlib.contextmanager
def dask_cluster(workers: int, folder: Path, env: dict[str, str] | None = None) -> Iterator[str]:
    """The address of a scheduler with `workers` single-threaded workers (one process each),
    their logs in `folder`; all stopped on exit."""
    from distributed import Client

    environment = {**os.environ, **(env or {}),
                   "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))}
    address = f"tcp://127.0.0.1:{_free_port()}"
    dask = [sys.executable, "-m", "dask"]
    processes = []
    try:
        with open(folder / "scheduler.log", "wb") as log:
            processes.append(subprocess.Popen(
                [*dask, "scheduler", "--host", "127.0.0.1", "--port", address.rsplit(":", 1)[1], "--no-dashboard"],
                env=environment, stdout=log, stderr=subprocess.STDOUT, cwd=folder))
        for number in range(workers):
            with open(folder / f"worker-{number}.log", "wb") as log:
                processes.append(subprocess.Popen(
                    [*dask, "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
                     "--name", f"farm-node-{number}", "--local-directory", str(folder / f"worker-{number}")],
                    env=environment, stdout=log, stderr=subprocess.STDOUT, cwd=folder))
        with Client(address, timeout="60s") as client:
            client.wait_for_workers(workers, timeout=120)
        yield address
    finally:
        for process in reversed(processes):
            process.terminate()
        for process in processes:
            try:
                process.wait(timeout=30)
            except subprocess.TimeoutExpired:
                process.kill()
