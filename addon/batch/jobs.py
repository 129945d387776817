"""The jobs file of `dimred batch`: one job a line, read as data and checked whole before any
job starts.

JSON Lines (`.jsonl`, `.json` or anything else): one object a line,

    {"id": "kitchen", "blend": "rooms/kitchen.blend", "op": "remove", "objects": ["Box", "Chair"],
     "params": {"quality": "final", "plane": ["Floor"]}}

CSV (`.csv`): a header row naming `blend`, `op` and `object` (several objects separated by `;`),
optionally `id`, and parameters as further columns (empty cells are left out).

Paths are taken literally (no `~`, variable or glob expansion), relative to the jobs file's
folder; nothing in a line is evaluated. Every bad line is reported with its number before any
job runs.
"""
from __future__ import annotations

import csv
import hashlib
import json
import math
import os
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass

from ..errors import DimredError
from ..quality import DESCRIPTIONS, working_width_problem

OPERATIONS = ("remove", "relocate", "align")
_ALL = frozenset(OPERATIONS)
_MOVING = frozenset({"remove", "relocate"})


@dataclass(frozen=True)
class _Param:
    """A job parameter: the operations that take it, its command line flag and its reader."""

    ops: frozenset[str]
    flag: str
    read: Callable[[object, str], object]  # (value, jobs file folder) -> canonical value; ValueError if bad


def _quality(value: object, _folder: str) -> str:
    if value not in DESCRIPTIONS:
        raise ValueError(f"must be one of {', '.join(DESCRIPTIONS)}")
    return str(value)


def _number(value: object, _folder: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | str):
        raise ValueError("must be a number")
    try:
        number = float(value)
    except ValueError:
        raise ValueError("must be a number") from None
    if not math.isfinite(number):
        raise ValueError("must be a finite number")
    return number


def _working_width(value: object, folder: str) -> int:
    number = _number(value, folder)
    width = int(number) if number == int(number) else number
    problem = working_width_problem(width)
    if problem:
        raise ValueError(problem)
    return width


def _flag(value: object, _folder: str) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip().lower() in ("true", "1", "yes", "false", "0", "no"):
        return value.strip().lower() in ("true", "1", "yes")
    raise ValueError("must be true or false")


def _names(value: object, _folder: str) -> tuple[str, ...]:
    names = value.split(";") if isinstance(value, str) else value
    if not isinstance(names, list | tuple) or not all(isinstance(n, str) and n.strip() for n in names):
        raise ValueError("must be a list of object names")
    return tuple(n.strip() for n in names)


def _vector(value: object, folder: str) -> tuple[float, float, float]:
    parts = value.split() if isinstance(value, str) else value
    if not isinstance(parts, list | tuple) or len(parts) != 3:
        raise ValueError("must be three numbers x, y, z")
    x, y, z = (_number(p, folder) for p in parts)
    return x, y, z


def _existing_file(value: object, folder: str) -> str:
    if not isinstance(value, str) or not value.strip():
        raise ValueError("must be a file path")
    path = os.path.normpath(os.path.join(folder, value))
    if not os.path.isfile(path):
        raise ValueError(f"no such file: {path}")
    return path


PARAMS: dict[str, _Param] = {
    "quality": _Param(_ALL, "--quality", _quality),
    "working_width": _Param(_MOVING, "--working-width", _working_width),
    "plane": _Param(_ALL, "--plane", _names),
    "center": _Param(_ALL, "--center", _vector),
    "fit_height": _Param(_ALL, "--fit-height", _flag),
    "align": _Param(_MOVING, "--align", _flag),
    "mask": _Param(_MOVING, "--mask", _existing_file),
    "yaw": _Param(frozenset({"relocate"}), "--yaw", _number),
    "distance_scale": _Param(frozenset({"relocate"}), "--distance-scale", _number),
    # A copy of the .blend with the corrected proxy, written into the job's folder as aligned.blend.
    "save": _Param(frozenset({"align"}), "--save", _flag),
}
SAVED_BLEND = "aligned.blend"

_FIELDS = ("id", "blend", "op", "object", "objects", "params")
_ID = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,99}")


@dataclass(frozen=True)
class Job:
    """One checked line of the jobs file."""

    line: int  # 1-based line of the jobs file (for CSV: counting the header)
    id: str  # the job's folder name under the batch's output folder
    blend: str  # absolute path of the .blend
    op: str  # one of OPERATIONS
    objects: tuple[str, ...]  # removed in this order; one for relocate and align
    params: str  # canonical JSON of the checked parameters (sorted keys)

    def parameters(self) -> dict:
        return json.loads(self.params)

    def arguments(self, out: str) -> list[str]:
        """The command line arguments after the .blend (`dimred OP ... --out OUT`)."""
        arguments = [self.op]
        for name in self.objects:
            arguments += ["--object", name]
        arguments += ["--out", out]
        for key, value in self.parameters().items():
            flag = PARAMS[key].flag
            if key == "save":
                arguments += [flag, os.path.join(out, SAVED_BLEND)] if value else []
            elif isinstance(value, bool):
                arguments += [flag] if value else []
            elif key == "plane":
                for name in value:
                    arguments += [flag, name]
            elif key == "center":
                arguments += [flag, *(repr(float(v)) for v in value)]
            else:
                arguments += [flag, repr(value) if isinstance(value, float) else str(value)]
        return arguments


class JobsFileError(DimredError):
    """The jobs file cannot be run; `problems` holds one "line N: ..." message per bad line."""

    def __init__(self, path: str, problems: Sequence[str]) -> None:
        self.problems = tuple(problems)
        super().__init__(f"{path}: " + "; ".join(self.problems))


def read_jobs(path: str) -> tuple[Job, ...]:
    """The jobs of the file at `path`, every line checked; JobsFileError lists every bad one."""
    path = os.path.abspath(path)
    try:
        with open(path, encoding="utf-8", newline="") as handle:
            text = handle.read()
    except (OSError, UnicodeDecodeError) as error:
        raise DimredError(f"cannot read the jobs file {path}: {getattr(error, 'strerror', None) or error}") from None
    folder = os.path.dirname(path)
    rows = _csv_rows(text) if path.lower().endswith(".csv") else _json_rows(text)
    jobs, problems = [], []
    for line, row in rows:
        try:
            jobs.append(_job(line, row, folder))
        except ValueError as error:
            problems.append(f"line {line}: {error}")
    seen: dict[str, int] = {}
    for job in jobs:
        if job.id in seen:
            problems.append(f"line {job.line}: id '{job.id}' is already the id of line {seen[job.id]}")
        seen.setdefault(job.id, job.line)
    if problems:
        raise JobsFileError(path, sorted(problems, key=_line_number))
    if not jobs:
        raise JobsFileError(path, ["holds no job"])
    return tuple(jobs)


def _line_number(problem: str) -> int:
    return int(problem.split()[1].rstrip(":"))


def _json_rows(text: str) -> list[tuple[int, object]]:
    rows: list[tuple[int, object]] = []
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        try:
            rows.append((number, json.loads(line)))
        except json.JSONDecodeError as error:
            rows.append((number, ValueError(f"not valid JSON ({error.msg} at column {error.colno})")))
    return rows


def _csv_rows(text: str) -> list[tuple[int, object]]:
    reader = csv.DictReader(text.splitlines())
    header = reader.fieldnames or []
    rows: list[tuple[int, object]] = []
    for row in reader:
        line = reader.line_num
        if None in row:
            rows.append((line, ValueError(f"has more cells than the header's {len(header)}")))
            continue
        cells = {k.strip(): v.strip() for k, v in row.items() if v is not None and v.strip()}
        if not cells:
            continue
        job = {k: cells.pop(k) for k in ("id", "blend", "op") if k in cells}
        if "object" in cells:
            job["objects"] = list(_names(cells.pop("object"), ""))
        job["params"] = cells
        rows.append((line, job))
    return rows


def _job(line: int, row: object, folder: str) -> Job:
    if isinstance(row, ValueError):
        raise row
    if not isinstance(row, dict):
        raise ValueError("must be a JSON object")
    unknown = sorted(set(row) - set(_FIELDS))
    if unknown:
        raise ValueError(f"unknown field '{unknown[0]}' (fields: {', '.join(_FIELDS)})")
    op = row.get("op")
    if op not in OPERATIONS:
        raise ValueError(f"'op' must be one of {', '.join(OPERATIONS)}" + (f", not '{op}'" if op else ""))
    blend = row.get("blend")
    if not isinstance(blend, str) or not blend.strip():
        raise ValueError("missing field 'blend' (the .blend file)")
    blend = os.path.normpath(os.path.join(folder, blend))
    if not os.path.isfile(blend):
        raise ValueError(f"no such .blend file: {blend}")
    objects = _objects(row)
    if op != "remove" and len(objects) != 1:
        raise ValueError(f"'{op}' takes one object, not {len(objects)}")
    params = row.get("params", {})
    if not isinstance(params, dict):
        raise ValueError("'params' must be a JSON object")
    checked = {}
    for key, value in params.items():
        spec = PARAMS.get(key)
        if spec is None:
            raise ValueError(f"unknown parameter '{key}' (parameters: {', '.join(PARAMS)})")
        if op not in spec.ops:
            raise ValueError(f"parameter '{key}' does not apply to '{op}'")
        try:
            checked[key] = spec.read(value, folder)
        except ValueError as error:
            raise ValueError(f"parameter '{key}' {error}") from None
    canonical = json.dumps(checked, sort_keys=True)
    job_id = row.get("id")
    if job_id is None:
        job_id = _default_id(blend, op, objects, canonical)
    elif not isinstance(job_id, str) or not _ID.fullmatch(job_id):
        raise ValueError("'id' must be 1-100 letters, digits, '.', '_' or '-', starting with a letter or digit")
    return Job(line=line, id=job_id, blend=blend, op=op, objects=objects, params=canonical)


def _objects(row: dict) -> tuple[str, ...]:
    if "object" in row and "objects" in row:
        raise ValueError("give 'object' or 'objects', not both")
    value = row.get("objects", [row["object"]] if "object" in row else None)
    if value is None:
        raise ValueError("missing field 'object' (the object's name)")
    if not isinstance(value, list) or not value or not all(isinstance(n, str) and n for n in value):
        raise ValueError("'objects' must be a list of object names")
    if len(set(value)) != len(value):
        raise ValueError("'objects' names an object twice")
    return tuple(value)


def _default_id(blend: str, op: str, objects: tuple[str, ...], params: str) -> str:
    """A readable id that stays the same when lines are reordered (the content's hash in it)."""
    content = json.dumps([blend, op, objects, params]).encode()
    stem = re.sub(r"[^A-Za-z0-9._-]+", "_", f"{os.path.splitext(os.path.basename(blend))[0]}-{op}-{objects[0]}")
    return f"{stem.strip('._-')[:80] or 'job'}-{hashlib.sha256(content).hexdigest()[:8]}"
