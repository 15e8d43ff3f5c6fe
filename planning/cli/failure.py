"""The CLI's exit codes and the one exception its commands raise to end with one of them."""

from __future__ import annotations

EXIT_OK, EXIT_INVALID, EXIT_NO_TRAJECTORY = 0, 2, 3


class CommandError(Exception):
    """A failure with its exit code and one-line message."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code
