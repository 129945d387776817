"""A benchmark's results: Markdown tables printed row by row as they are measured, then written
whole into docs/results/<benchmark>.md under a line naming the command that produced them.

    table = Table(["preset", "seconds"], title="basic_box 1024x512")
    table.row("balanced", f"{seconds:.2f}")
    write(table)

The docs' result tables are these files: run the benchmark again to refresh one, never edit it
by hand.
"""
from __future__ import annotations

import os
import platform
import shlex
import sys
import time
from collections.abc import Sequence
from pathlib import Path

RESULTS = Path(__file__).resolve().parents[1] / "docs" / "results"


class Table:
    """One Markdown table: its title line and header are printed when it is made, each row when
    it is added (a run of minutes shows its rows as they come)."""

    def __init__(self, columns: Sequence[str], *, title: str = "") -> None:
        self.title = title
        self.lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
        print("\n".join((["", title, ""] if title else [""]) + self.lines), flush=True)

    def row(self, *cells: object) -> None:
        """Add a row of cells, each written with str()."""
        self.lines.append("| " + " | ".join(str(c) for c in cells) + " |")
        print(self.lines[-1], flush=True)

    def markdown(self) -> str:
        return "\n".join(([self.title, ""] if self.title else []) + self.lines)


def command_line(argv: Sequence[str] | None = None) -> str:
    """The command that ran this benchmark, from the repository root."""
    argv = sys.argv if argv is None else argv
    return shlex.join([".venv/bin/python", f"benchmarks/{Path(argv[0]).name}", *argv[1:]])


def write(*tables: Table, notes: Sequence[str] = (), folder: Path = RESULTS, argv: Sequence[str] | None = None) -> Path:
    """Write `tables` (and `notes`, lines printed after them) into folder/<benchmark>.md, the
    benchmark named by its script; returns the path."""
    argv = sys.argv if argv is None else argv
    name = Path(argv[0]).stem
    when = time.strftime("%Y-%m-%d", time.gmtime())
    head = (f"# {name}\n\nWritten by `{command_line(argv)}` on {when} "
            f"({platform.system()} {platform.machine()}, {os.cpu_count()} CPUs).\n")
    body = "\n\n".join(t.markdown() for t in tables)
    tail = "".join(f"\n{line}\n" for line in notes)
    for line in notes:
        print(line)
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{name}.md"
    path.write_text(f"{head}\n{body}\n{tail}")
    print(f"written: {path}", file=sys.stderr)
    return path
