"""How a run talks to whoever started it: progress, cancellation and previews, in one object.

The command line passes none of them, the Blender operator all three (from its worker thread),
and a relocation hands each of its solves a view of its own callbacks with the progress scaled
to that solve's share of the run. Every stage takes the one object instead of three arguments.
"""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Any

from .errors import Cancelled

if TYPE_CHECKING:  # the operators import this module when they register: keep it free of numpy
    import numpy as np

ProgressFn = Callable[[str, float], None]
CancelFn = Callable[[], bool]
PreviewFn = Callable[[Any], None]


@dataclass(frozen=True)
class RunCallbacks:
    """`progress(stage, fraction)` with fraction in [0, 1]; `cancel()` True to stop (checked
    between steps, which then raise `Cancelled`); `preview(difference)` with an (H, W, 3)
    float32 difference image before the result (or whatever the caller's own layer made of it:
    the Blender side hands on pixel buffers). Each may be None."""

    progress: ProgressFn | None = None
    cancel: CancelFn | None = None
    preview: PreviewFn | None = None

    def check(self) -> None:
        """Raise `Cancelled` when the caller asked to stop."""
        if self.cancel is not None and self.cancel():
            raise Cancelled()

    def show(self, difference: np.ndarray) -> None:
        if self.preview is not None:
            self.preview(difference)

    def scaled(self, low: float, high: float, prefix: str) -> RunCallbacks:
        """These callbacks for a part of the run that spans [low, high] of its progress, its
        stage names prefixed (a relocation's removal and insertion passes)."""
        progress = self.progress
        if progress is None:
            return self
        return replace(self, progress=lambda stage, fraction: progress(f"{prefix}{stage}",
                                                                        low + (high - low) * fraction))

    def mapped_preview(self, transform: Callable[[np.ndarray], np.ndarray]) -> RunCallbacks:
        """These callbacks with each preview image passed through `transform` first."""
        preview = self.preview
        if preview is None:
            return self
        return replace(self, preview=lambda difference: preview(transform(difference)))


NO_CALLBACKS = RunCallbacks()
