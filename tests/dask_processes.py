"""A real Dask cluster as a farm runs it: `dask scheduler` and `dask worker` processes started
from the command line on localhost, the workers with this checkout on their Python path, over
plain TCP or over TLS with certificates made by `openssl`."""
from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

from addon.batch.cluster import TLSFiles

ROOT = Path(__file__).resolve().parents[1]


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def make_certificates(folder: Path) -> TLSFiles:
    """A certificate authority and one key and certificate it signed, for every member of a
    test cluster (a farm would give each machine its own)."""
    def openssl(*arguments: str) -> None:
        subprocess.run(["openssl", *arguments], cwd=folder, check=True, capture_output=True, timeout=120)

    openssl("req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "2", "-subj", "/CN=dimred test CA",
            "-keyout", "ca-key.pem", "-out", "ca.pem")
    openssl("req", "-newkey", "rsa:2048", "-nodes", "-subj", "/CN=localhost", "-keyout", "key.pem", "-out", "req.pem")
    openssl("x509", "-req", "-in", "req.pem", "-CA", "ca.pem", "-CAkey", "ca-key.pem", "-CAcreateserial", "-days", "2",
            "-out", "cert.pem")
    return TLSFiles(ca_file=str(folder / "ca.pem"), cert=str(folder / "cert.pem"), key=str(folder / "key.pem"))


@contextlib.contextmanager
def dask_cluster(workers: int, folder: Path, env: dict[str, str] | None = None, *,
                 tls: TLSFiles | None = None, project_on_path: bool = True) -> Iterator[str]:
    """The address of a scheduler with `workers` single-threaded workers (one process each),
    their logs in `folder`, speaking TLS with `tls`'s certificates if given, the checkout on
    their Python path unless not `project_on_path`; all stopped on exit."""
    from distributed import Client
    from distributed.security import Security

    environment = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    environment.update(env or {})
    if project_on_path:
        environment["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")]))
    port = str(_free_port())
    address = f"{'tls' if tls else 'tcp'}://127.0.0.1:{port}"
    certificates = [] if tls is None else ["--tls-ca-file", tls.ca_file, "--tls-cert", tls.cert, "--tls-key", tls.key]
    dask = [sys.executable, "-m", "dask"]
    processes = []
    try:
        with open(folder / "scheduler.log", "wb") as log:
            protocol = ["--protocol", "tls"] if tls else []
            processes.append(subprocess.Popen(
                [*dask, "scheduler", "--host", "127.0.0.1", "--port", port, "--no-dashboard", *protocol,
                 *certificates], env=environment, stdout=log, stderr=subprocess.STDOUT, cwd=folder))
        for number in range(workers):
            with open(folder / f"worker-{number}.log", "wb") as log:
                processes.append(subprocess.Popen(
                    [*dask, "worker", address, "--nworkers", "1", "--nthreads", "1", "--no-dashboard",
                     "--name", f"farm-node-{number}", "--local-directory", str(folder / f"worker-{number}"),
                     *certificates], env=environment, stdout=log, stderr=subprocess.STDOUT, cwd=folder))
        security = None if tls is None else Security(tls_ca_file=tls.ca_file, tls_client_cert=tls.cert,
                                                      tls_client_key=tls.key, require_encryption=True)
        with Client(address, timeout="60s", security=security) as client:
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
