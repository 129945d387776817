"""Jobs run on Dask's distributed scheduler: a local cluster of worker processes on this
machine, or a running cluster (`--scheduler tcp://HOST:8786`, `tls://...` with certificates).

Dask lives in the development and command line environment only (requirements.txt), never in
the extension: this module imports it when a batch asks for it. Each Dask task is `run_job`,
which starts the job's own child process on the worker's machine, so a Blender crash takes
down that child, never the worker. Workers of a remote cluster need the same environment, the
project on their Python path and the .blend files and output folder at the same paths.
"""
from __future__ import annotations

import ipaddress
import urllib.parse
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ..errors import DimredError
from .execute import Record, Task, pending, run_job

#: The resource a worker may declare (`dask worker ... --resources MEMORY=16e9`): tasks then
#: reserve their memory estimate of it, as the local scheduler does.
MEMORY_RESOURCE = "MEMORY"


@dataclass(frozen=True)
class TLSFiles:
    """The certificates of a TLS connection to the scheduler (Dask's `Security`)."""

    ca_file: str
    cert: str
    key: str


def dask_available() -> bool:
    try:
        import distributed  # noqa: F401
    except ImportError:
        return False
    return True


def run_dask(tasks: Sequence[Task], needs: Sequence[int], *, scheduler: str | None, workers: int,
             tls: TLSFiles | None, on_done: Callable[[Record], None]) -> None:
    """Run `tasks` on a local cluster of `workers` single-threaded processes listening on
    127.0.0.1 only (`scheduler` None) or on the cluster at `scheduler` (its address checked by
    `check_address` first); `on_done` gets each record as it comes back, on the calling thread."""
    try:
        from distributed import Client, LocalCluster, as_completed
        from distributed.security import Security
    except ImportError:
        raise DimredError("Dask is not installed in this environment: install requirements.txt, or run without "
                          "--scheduler (jobs then run as local processes)") from None
    security = None if tls is None else Security(tls_ca_file=tls.ca_file, tls_client_cert=tls.cert,
                                                  tls_client_key=tls.key, require_encryption=True)
    cluster = None
    try:
        if scheduler is None:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                                   dashboard_address=None, silence_logs=40)
        client = Client(cluster if cluster is not None else scheduler, security=security, timeout="30s")
    except (OSError, TimeoutError) as error:
        if cluster is not None:
            cluster.close()
        raise DimredError(f"cannot reach the Dask scheduler {scheduler or '(local)'}: {error}") from None
    try:
        _check_workers_import(client)
        declared = _memory_declared(client)
        futures = {}
        for task, need in zip(tasks, needs, strict=True):
            resources = {MEMORY_RESOURCE: need} if declared else None
            future = client.submit(run_job, task, key=f"dimred-{task.job.id}-{task.fingerprint[:12]}", pure=False,
                                   resources=resources)
            futures[future] = task
        try:
            for future in as_completed(futures):
                task = futures[future]
                try:
                    record = future.result()
                except Exception as error:  # the worker died or the task could not be unpickled
                    record = pending(task.job, "failed", f"the Dask worker could not run the job: {error}")
                on_done(record)
        except KeyboardInterrupt:
            client.cancel(list(futures), force=True)
            raise
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _check_workers_import(client) -> None:
    """DimredError unless every worker can import the job runner: a task it cannot unpickle
    would only be retried on the next worker, and the batch would wait for ever."""
    import pkgutil

    target = f"{run_job.__module__}:{run_job.__name__}"
    try:
        # pkgutil.resolve_name is the standard library's (importable on any worker) and returns
        # something a worker can send back: the function, pickled by reference.
        client.run(pkgutil.resolve_name, target)
    except Exception as error:
        raise DimredError(f"the Dask workers cannot import {run_job.__module__} ({type(error).__name__}: {error}): "
                          "start them from this project's environment with the checkout on PYTHONPATH") from None


def _memory_declared(client) -> bool:
    """Whether every worker declares the MEMORY resource (if one does not, a task asking for it
    could wait there forever)."""
    workers = client.scheduler_info().get("workers", {})
    return bool(workers) and all(MEMORY_RESOURCE in w.get("resources", {}) for w in workers.values())


def check_address(address: str, tls: TLSFiles | None, *, warn: Callable[[str], None]) -> None:
    """DimredError for an address the batch cannot or should not use; `warn` about one reached
    unencrypted over the network."""
    parsed = urllib.parse.urlparse(address)
    if parsed.scheme not in ("tcp", "tls") or not parsed.hostname:
        raise DimredError(f"--scheduler {address}: give tcp://HOST:PORT or tls://HOST:PORT")
    if tls is not None and parsed.scheme != "tls":
        raise DimredError(f"--scheduler {address}: the TLS certificates need a tls:// address")
    if tls is None and parsed.scheme == "tls":
        raise DimredError(f"--scheduler {address}: a tls:// scheduler needs --tls-ca-file, --tls-cert and --tls-key")
    if tls is None and not _is_loopback(parsed.hostname):
        warn(f"the connection to {address} is not encrypted and not authenticated: anyone on the network who "
             "reaches the scheduler can run code on its workers; use tls:// with certificates")


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
