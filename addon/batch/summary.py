"""The batch's tables, `summary.csv` and `summary.json`: one row per job of the jobs file in its
order, rewritten (under a temporary name, then renamed) each time a job ends, so a killed batch
leaves a summary of what it had finished."""
from __future__ import annotations

import csv
import json
import os
from collections.abc import Sequence

from .execute import Record

COLUMNS = ("id", "line", "op", "objects", "status", "reused", "seconds", "peak_memory_mb")
#: The report's figures as columns, after COLUMNS and before the error.
FIGURES = ("width", "height", "engine_seconds", "hidden_pixels", "hidden_region_filled", "bounces", "warnings",
           "elevation_change_deg",
           "alignment_shift_cm", "alignment_turn_deg", "alignment_scale_percent")


def write_summary(out: str, records: Sequence[Record], *, meta: dict) -> None:
    """summary.json (`meta` and the records) and summary.csv in `out`."""
    counts = {status: sum(r.status == status for r in records) for status in sorted({r.status for r in records})}
    payload = {**meta, "jobs": len(records), "counts": counts, "records": [r.as_dict() for r in records]}
    _replace(os.path.join(out, "summary.json"), lambda handle: json.dump(payload, handle, indent=2))

    def table(handle) -> None:
        writer = csv.writer(handle)
        writer.writerow([*COLUMNS, *FIGURES, "error"])
        for r in records:
            row = [r.id, r.line, r.op, ";".join(r.objects), r.status, str(r.reused).lower(),
                   "" if r.seconds is None else f"{r.seconds:.2f}",
                   "" if r.peak_memory_mb is None else f"{r.peak_memory_mb:.0f}"]
            writer.writerow([*row, *(_cell(r.figures.get(name)) for name in FIGURES), r.error])

    _replace(os.path.join(out, "summary.csv"), table)


def _cell(value: object) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, list | tuple):
        return ";".join(_cell(v) for v in value)
    return str(value)


def _replace(path: str, write) -> None:
    temporary = f"{path}.writing"
    with open(temporary, "w", encoding="utf-8", newline="") as handle:
        write(handle)
    os.replace(temporary, path)
