"""The one exception type the engine, bridge and command line raise for bad input.

Its message is the single line shown to the user (stderr, operator report); whoever catches
it exits non-zero and writes nothing.
"""


class DimredError(Exception):
    """Bad input or a cancelled run: the message says what and, where it can, how to fix it."""


class Cancelled(DimredError):
    """The user (or a caller's cancel callback) stopped the run."""

    def __init__(self, message: str = "cancelled by the user; nothing was changed") -> None:
        super().__init__(message)
