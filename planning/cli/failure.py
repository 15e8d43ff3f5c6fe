"""The CLI's exit codes and the one exception its commands raise to end with one of them."""

from __future__ import annotations

EXIT_OK, EXIT_INVALID, EXIT_NO_TRAJECTORY, EXIT_INTERNAL = 0, 2, 3, 4
"""Success; invalid input; no trajectory found (or, for ``check``, one that fails); an
unexpected error (a bug, or a crashed batch worker)."""
EXIT_INTERRUPTED = 130
"""Stopped by ``Ctrl-C`` or ``SIGTERM`` (128 + SIGINT, as shells report it)."""


class CommandError(Exception):
    """A failure with its exit code and one-line message."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code
