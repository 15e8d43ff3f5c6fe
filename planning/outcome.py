"""What a failure means to a user: one mapping from exceptions to statuses and exit codes.

Every command of ``cpr-plan`` and every scene of a batch (:mod:`planning.batch`) classifies
what stopped it here, and nowhere else:

====================  ===============  =====  =====================================================
status                exit code        what   raised as
====================  ===============  =====  =====================================================
``ok``                0                done
``invalid``           2                input  :class:`~planning.errors.PlanningError`,
                                              :class:`cpr_kin.CprKinError`, :class:`OSError`
``no_trajectory``     3                none   :class:`~planning.errors.NoSolutionError`
``error``             4                bug    any other exception
``crashed``           4                bug    a batch worker died (no exception reaches us)
``interrupted``       130              user   ``Ctrl-C`` or ``SIGTERM`` (:class:`KeyboardInterrupt`,
                                              also when it surfaces wrapped, e.g. as the cause
                                              of a compiled function's ``SystemError``)
====================  ===============  =====  =====================================================
"""

from __future__ import annotations

from dataclasses import dataclass

from cpr_kin.common.errors import CprKinError
from cpr_kin.common.names import escaped
from planning.errors import NoSolutionError, PlanningError

EXIT_OK, EXIT_INVALID, EXIT_NO_TRAJECTORY, EXIT_INTERNAL = 0, 2, 3, 4
"""Success; invalid input; no trajectory found (or, for ``check``, one that fails); an
unexpected error (a bug, or a crashed batch worker)."""
EXIT_INTERRUPTED = 130
"""Stopped by ``Ctrl-C`` or ``SIGTERM`` (128 + SIGINT, as shells report it)."""

STATUS_EXIT = {
    "ok": EXIT_OK,
    "invalid": EXIT_INVALID,
    "no_trajectory": EXIT_NO_TRAJECTORY,
    "error": EXIT_INTERNAL,
    "crashed": EXIT_INTERNAL,
    "interrupted": EXIT_INTERRUPTED,
}
"""Each status's exit code."""


class Interrupted(KeyboardInterrupt):
    """An interrupt that says what it left on disk (e.g. "the new set in 'out' is complete")."""


@dataclass(frozen=True)
class Outcome:
    """A failure, classified.

    Attributes:
        status: one of :data:`STATUS_EXIT`'s keys.
        exit_code: its exit code.
        message: one line for the user, control characters escaped.
    """

    status: str
    exit_code: int
    message: str


def interruption(error: BaseException) -> KeyboardInterrupt | None:
    """The :class:`KeyboardInterrupt` that ``error`` is or was caused by, if any.

    A signal handler that raises while a compiled function runs makes CPython report a
    ``SystemError`` whose cause is the interrupt.
    """
    seen: set[int] = set()
    current: BaseException | None = error
    while current is not None and id(current) not in seen:
        if isinstance(current, KeyboardInterrupt):
            return current
        seen.add(id(current))
        current = current.__cause__ or current.__context__
    return None


def describe(error: BaseException) -> str:
    """The message of ``error`` for a user: a file error names its file."""
    if isinstance(error, OSError) and not isinstance(error, PlanningError | CprKinError):
        where = f" '{error.filename}'" if error.filename else ""
        return f"cannot use{where}: {error.strerror or error}"
    return str(error)


def classify(error: BaseException) -> Outcome:
    """The status, exit code and message of what stopped a command or a scene."""
    if interruption(error) is not None:
        status, message = "interrupted", "interrupted"
    elif isinstance(error, NoSolutionError):
        status, message = "no_trajectory", describe(error)
    elif isinstance(error, PlanningError | CprKinError | OSError):
        status, message = "invalid", describe(error)
    else:
        status, message = "error", f"{type(error).__name__}: {error}"
    return Outcome(status, STATUS_EXIT[status], escaped(" ".join(message.split())))
