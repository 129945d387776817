"""The batch of 20 jobs over the ground-truth scenes that the batch's test and benchmark run
(removals, several objects removed in order, relocations, alignments, one damaged .blend, one
unknown object), and each job as the single command line a user would type instead."""
from __future__ import annotations

import json
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

from . import spec as S
from .render import REPO, render_pair

SCENES = ["basic_box", "red_box", "stool", "wall_contact", "bright_lamp", "seam", "rotated_world", "second_object"]
DRAFT = {"quality": "draft"}


def batch_jobs(folder: Path, *, removals: Sequence[str] = SCENES) -> list[dict]:
    """The jobs, over the cached renders of SCENES (rendered here when missing): a draft removal
    of each of `removals` (all of SCENES: the 20 jobs), then the 12 others."""
    blends = {name: str(render_pair(S.get(name))["blend"]) for name in SCENES}
    removed = {name: S.get(name).remove for name in SCENES}
    damaged = folder / "damaged.blend"
    damaged.write_bytes(b"BLENDER-v402" + bytes(range(256)) * 4)  # a header, then nothing Blender can read
    jobs = [{"id": f"{name}-remove", "blend": blends[name], "op": "remove", "object": removed[name],
             "params": DRAFT} for name in removals]
    jobs += [
        {"id": "basic_box-balanced", "blend": blends["basic_box"], "op": "remove", "object": "Box"},
        {"id": "second_object-both", "blend": blends["second_object"], "op": "remove", "objects": ["Box", "Cabinet"],
         "params": DRAFT},
        {"id": "rotated_world-floor", "blend": blends["rotated_world"], "op": "remove", "object": "Box",
         "params": {**DRAFT, "plane": ["Floor"]}},
        {"id": "seam-aligned", "blend": blends["seam"], "op": "remove", "object": "Box",
         "params": {**DRAFT, "align": True}},
    ]
    for name, yaw, scale in [("basic_box", 40.0, 1.3), ("stool", 40.0, 1.3), ("red_box", 25.0, 0.8),
                             ("wall_contact", -40.0, 1.3)]:
        jobs.append({"id": f"{name}-move", "blend": blends[name], "op": "relocate", "object": removed[name],
                     "params": {**DRAFT, "yaw": yaw, "distance_scale": scale}})
    jobs += [
        {"id": "basic_box-align", "blend": blends["basic_box"], "op": "align", "object": "Box",
         "params": {"save": True}},
        {"id": "wall_contact-align", "blend": blends["wall_contact"], "op": "align", "object": "Crate"},
        {"id": "damaged", "blend": str(damaged), "op": "remove", "object": "Box"},
        {"id": "unknown-object", "blend": blends["basic_box"], "op": "remove", "object": "Sofa"},
    ]
    return jobs


def cli(*arguments: str, timeout: float = 900) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "addon.cli", *arguments], cwd=REPO, capture_output=True, text=True,
                          timeout=timeout)


def single(job: dict, out: Path) -> subprocess.CompletedProcess:
    """The job as one command line."""
    arguments = [job["op"], job["blend"]]
    for name in job.get("objects", [job.get("object")]):
        arguments += ["--object", name]
    for key, value in job.get("params", {}).items():
        flag = "--" + key.replace("_", "-")
        if value is True:
            arguments.append(flag)
        elif isinstance(value, list):
            for item in value:
                arguments += [flag, item]
        else:
            arguments += [flag, str(value)]
    return cli(*arguments, "--out", str(out))


def write_jobs_file(folder: Path, *, removals: Sequence[str] = SCENES) -> tuple[Path, list[dict]]:
    """folder/jobs.jsonl holding `batch_jobs(folder, removals=removals)`, and the jobs."""
    jobs = batch_jobs(folder, removals=removals)
    path = folder / "jobs.jsonl"
    path.write_text("".join(json.dumps(j) + "\n" for j in jobs), encoding="utf-8")
    return path, jobs
