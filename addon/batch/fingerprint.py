"""What a job's result depends on, as one hash: the contents of the .blend and of the files it
reads (the panorama, the artist's mask), the operation and its parameters, and the add-on's
version. A re-run batch keeps a finished job whose fingerprint is unchanged."""
from __future__ import annotations

import hashlib
import json
import os
import tomllib
from collections.abc import Mapping
from functools import cache

from .jobs import Job

_CHUNK = 1 << 20


def file_digest(path: str) -> str:
    """sha256 of the file's bytes, read a megabyte at a time (panoramas run to gigabytes)."""
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        while chunk := handle.read(_CHUNK):
            digest.update(chunk)
    return digest.hexdigest()


def job_fingerprint(job: Job, inputs: Mapping[str, str], *, version: str) -> str:
    """The hash of `job`'s operation, objects and parameters, the `inputs` (path -> digest of
    every file it reads, the .blend included) and the add-on `version`. The paths themselves
    are left out: a folder of scenes moved elsewhere keeps its results."""
    content = {"op": job.op, "objects": list(job.objects), "params": job.parameters(),
               "inputs": sorted(inputs.values()), "version": version}
    return hashlib.sha256(json.dumps(content, sort_keys=True).encode()).hexdigest()


@cache
def addon_version() -> str:
    """The version in the extension's manifest (beside the `addon` package)."""
    manifest = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(__file__))), "blender_manifest.toml")
    try:
        with open(manifest, "rb") as handle:
            return str(tomllib.load(handle)["version"])
    except (OSError, KeyError, tomllib.TOMLDecodeError):
        # A copy without its manifest: results are then kept only while nothing else changes.
        return "unknown"
