"""The exception types the engine, the reader and the command line raise.

`DimredError` is bad input: its message is the single line shown to the user (stderr,
operator report); whoever catches it exits non-zero and writes nothing. `Cancelled` is not bad
input: the user stopped the run, and nothing was changed.
"""


class DimredError(Exception):
    """Bad input: the message says what and, where it can, how to fix it."""


class Cancelled(Exception):
    """The user (or a caller's cancel callback) stopped the run."""

    def __init__(self, message: str = "cancelled by the user; nothing was changed") -> None:
        super().__init__(message)
