"""The batch's progress on a terminal: one line redrawn in place with the jobs done, failed and
running and the time left; on anything but a terminal, one plain line per job that ends."""
from __future__ import annotations

import time
from typing import TextIO

from .execute import Record

_WIDTH = 24


class Progress:
    """Counts the jobs of a batch as they end and draws them on `stream`."""

    def __init__(self, stream: TextIO, *, total: int, workers: int) -> None:
        self._stream, self._total, self._workers = stream, total, max(workers, 1)
        self._tty = bool(getattr(stream, "isatty", lambda: False)())
        self._done = self._failed = self._reused = 0
        self._run_seconds: list[float] = []
        self._start = time.monotonic()

    def ended(self, record: Record) -> None:
        if record.status == "done":
            self._done += 1
            self._reused += record.reused
            if not record.reused and record.seconds is not None:
                self._run_seconds.append(record.seconds)
        else:
            self._failed += 1
        if self._tty:
            self._stream.write("\r" + self.line())
        else:
            outcome = "kept" if record.reused else record.status
            self._stream.write(f"dimred batch: {record.id} {outcome}" + (f": {record.error}" if record.error else "")
                               + f" ({self._done + self._failed}/{self._total})\n")
        self._stream.flush()

    def line(self) -> str:
        ended = self._done + self._failed
        filled = round(_WIDTH * ended / max(self._total, 1))
        left = self.seconds_left()
        eta = "" if left is None else f", {_duration(left)} left"
        kept = f" ({self._reused} kept)" if self._reused else ""
        return (f"[{'#' * filled}{'.' * (_WIDTH - filled)}] {ended}/{self._total}: {self._done} done{kept}, "
                f"{self._failed} failed{eta}   ")

    def seconds_left(self) -> float | None:
        """The jobs not ended times the mean seconds of the jobs run so far, over the workers."""
        if not self._run_seconds:
            return None
        remaining = self._total - self._done - self._failed
        return remaining * (sum(self._run_seconds) / len(self._run_seconds)) / self._workers

    def close(self) -> None:
        if self._tty:
            self._stream.write("\n")
            self._stream.flush()


def _duration(seconds: float) -> str:
    seconds = round(seconds)
    if seconds < 60:
        return f"{seconds} s"
    minutes, seconds = divmod(seconds, 60)
    if minutes < 60:
        return f"{minutes} min {seconds:02d} s"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h {minutes:02d} min"
