"""A critical section that a signal does not cut in two: ``SIGINT`` and ``SIGTERM`` wait for its end.

Swapping a published set of files in place takes two renames and the removal of the set it
replaces. A signal between them would leave a hidden ``.out.old-*`` folder behind, and a
user told "nothing written" while the new set is in place. Within :func:`uninterrupted`
the two signals are only recorded; when the section ends, the handlers that were in place
come back and each recorded signal is raised again, so that it then does what it would
have done (a command line's handler raises :class:`KeyboardInterrupt`; Python's default
stops the process).
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator
from types import FrameType

DEFERRED = (signal.SIGINT, signal.SIGTERM)


@contextlib.contextmanager
def uninterrupted() -> Iterator[None]:
    """Defer :data:`DEFERRED` until the end of the context.

    Only the main thread runs signal handlers (and may set them); in another thread this
    is a no-op.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    pending: list[int] = []

    def defer(signum: int, _frame: FrameType | None) -> None:
        pending.append(signum)

    previous = {signum: signal.signal(signum, defer) for signum in DEFERRED}
    try:
        yield
    finally:
        for deferred, handler in previous.items():
            signal.signal(deferred, handler)
        for signum in dict.fromkeys(pending):
            signal.raise_signal(signum)
