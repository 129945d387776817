"""The command line's `batch` and `inspect` commands.

    python -m addon.cli batch JOBS --out DIR [--workers N] [--scheduler ADDRESS] [--timeout S]
    blender -b -c dimred batch JOBS --out DIR ...   (jobs as local Blender processes, no Dask)
    python -m addon.cli inspect SCENE.blend [...]   (one JSON line per scene)
"""
from __future__ import annotations

import argparse
import json
import os
import sys

from ..errors import DimredError

_BATCH_DESCRIPTION = """\
Run many removals, relocations and alignments, one job a line of JOBS (JSON Lines, or CSV with
a header), each in its own process. Every job writes DIR/<id>/ (the files the single command
writes, plus job.json); the batch writes DIR/summary.csv and DIR/summary.json (status, seconds,
peak memory, the report's main figures, the error of a failed job) and each job's output in
DIR/logs/<id>.log. A job line:

  {"id": "kitchen", "blend": "rooms/kitchen.blend", "op": "remove", "objects": ["Box", "Chair"],
   "params": {"quality": "final", "plane": ["Floor"]}}

ops: remove (several objects are removed in order), relocate (params yaw, distance_scale) and
align (params save: write DIR/<id>/aligned.blend); params of all: quality, plane, center,
fit_height, and for remove and relocate: align, mask. Paths are relative to JOBS's folder.

Run again, the batch keeps every job whose folder is complete and whose inputs (the contents
of the .blend, its panorama and mask, the parameters, the add-on's version) are unchanged; a
killed batch loses only the jobs in flight. Jobs at once follow the memory each panorama needs.
Exit status: the number of jobs that did not finish (at most 100); 2 with nothing run when
JOBS or an option is bad."""

_BATCH_EPILOG = """\
engines:
  python -m addon.cli batch, no --scheduler: a Dask cluster of --workers processes on this
      machine, listening on 127.0.0.1 only (local processes where Dask is not installed)
  --scheduler tcp://HOST:8786 or tls://HOST:8786: a running Dask cluster whose workers have
      this project's environment and see the .blend files and DIR at the same paths
  blender -b -c dimred batch: local Blender processes (Blender's Python has no Dask)

examples:
  python -m addon.cli batch jobs.jsonl --out results/ --workers 4 --timeout 1800
  python -m addon.cli batch jobs.jsonl --out /farm/results --scheduler tls://farm:8786 \\
      --tls-ca-file ca.pem --tls-cert client.pem --tls-key client-key.pem
  blender -b -c dimred batch jobs.csv --out results/"""

#: The exit status counts failed jobs up to this.
MAX_FAILED_STATUS = 100


def add_commands(commands: argparse._SubParsersAction, *, formatter: type[argparse.HelpFormatter],
                 inside_blender: bool) -> None:
    """The `batch` and `inspect` subcommands; `inside_blender` (`blender -c dimred`): the jobs
    run as local processes, never on Dask (the extension does not ship it, and a Dask worker
    could not import the installed extension's package)."""
    batch = commands.add_parser("batch", help="run a file of jobs, resumable, on local processes or a Dask cluster",
                                description=_BATCH_DESCRIPTION, epilog=_BATCH_EPILOG, formatter_class=formatter)
    batch.add_argument("jobs", metavar="JOBS", help="the jobs file (.jsonl, or .csv with a header)")
    batch.add_argument("--out", required=True, metavar="DIR", help="output folder (created if needed)")
    batch.add_argument("--workers", type=int, default=os.cpu_count() or 1, metavar="N",
                       help="jobs at once on this machine at most (default: the CPU count; fewer when the "
                            "panoramas would not fit the free memory)")
    batch.add_argument("--scheduler", metavar="ADDRESS",
                       help="a running Dask scheduler (tcp://HOST:8786, or tls://HOST:8786 with the certificates)")
    batch.add_argument("--timeout", type=float, metavar="S", help="seconds a job may run before it is stopped")
    batch.add_argument("--tls-ca-file", metavar="FILE", help="the certificate authority of the cluster's certificates")
    batch.add_argument("--tls-cert", metavar="FILE", help="this client's certificate")
    batch.add_argument("--tls-key", metavar="FILE", help="this client's private key")
    batch.set_defaults(run=_batch, inside_blender=inside_blender)
    inspect = commands.add_parser(
        "inspect", help="print each scene's panorama size and the files it reads (JSON lines)",
        description="Print one JSON line per scene: {\"blend\", \"size\": [width, height], \"files\": [the "
                    "panorama's file]}, or {\"blend\", \"error\"} when it cannot be run. What `batch` reads "
                    "before it plans its jobs.", formatter_class=formatter)
    inspect.add_argument("blends", nargs="+", metavar="SCENE.blend")
    inspect.set_defaults(run=_inspect)


def _batch(args: argparse.Namespace) -> int:
    from ..batch.batch import BatchSettings, run_batch
    from ..batch.cluster import TLSFiles
    from ..batch.execute import Launcher
    from ..batch.jobs import JobsFileError

    tls_files = (args.tls_ca_file, args.tls_cert, args.tls_key)
    if any(tls_files) and not all(tls_files):
        raise DimredError("TLS needs all three of --tls-ca-file, --tls-cert and --tls-key")
    for path in filter(None, tls_files):
        if not os.path.isfile(path):
            raise DimredError(f"no such file: {path}")
    settings = BatchSettings(out=args.out, workers=args.workers, scheduler=args.scheduler, timeout=args.timeout,
                             tls=TLSFiles(*tls_files) if all(tls_files) else None,
                             launcher=Launcher(blender=_blender_executable()), use_dask=not args.inside_blender)
    try:
        result = run_batch(args.jobs, settings)
    except JobsFileError as error:
        for problem in error.problems:
            print(f"dimred: error: {os.path.abspath(args.jobs)} {problem}", file=sys.stderr)
        print(f"dimred: error: {len(error.problems)} bad job line(s); no job was run", file=sys.stderr, flush=True)
        return 2
    done = sum(r.status == "done" for r in result.records)
    kept = sum(r.reused for r in result.records)
    print(f"dimred: batch of {len(result.records)} jobs: {done} done ({kept} kept from an earlier run), "
          f"{result.failed} failed; wrote {os.path.abspath(args.out)}", flush=True)
    return min(result.failed, MAX_FAILED_STATUS)


def _blender_executable() -> str:
    """The Blender executable running this command, "" under the bpy module (no executable of
    its own: the jobs then run `python -m addon.cli`)."""
    if "bpy" not in sys.modules:
        return ""
    import bpy

    path = bpy.app.binary_path
    return path if path and os.path.isfile(path) else ""


def _inspect(args: argparse.Namespace) -> int:
    import bpy

    from . import reader
    from .blend_file import open_blend

    for blend in args.blends:
        path = os.path.abspath(blend)
        try:
            open_blend(path)
            scene = bpy.context.scene
            size = reader.panorama_size(scene)
            record = {"blend": path, "size": list(size), "files": [f for f in [reader.panorama_file(scene)] if f]}
        except DimredError as error:
            record = {"blend": path, "error": " ".join(str(error).split())}
        print(json.dumps(record), flush=True)
    return 0
