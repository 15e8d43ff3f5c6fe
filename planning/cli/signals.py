"""``Ctrl-C`` and ``SIGTERM`` as one interrupt, wherever it strikes.

While a command runs, both signals raise :class:`KeyboardInterrupt` (also when a shell
started the command in the background with ``SIGINT`` ignored) and are recorded: an
interrupt that surfaces as another exception (a compiled function reports it as a
``SystemError``) is still an interrupt (:func:`planning.outcome.interruption`). When the
command is over, a late signal is ignored: the process is exiting with its own code, and a
traceback would only hide it.
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Callable, Iterator
from types import FrameType

SIGNALS = (signal.SIGINT, signal.SIGTERM)


def _late(_signum: int, _frame: FrameType | None) -> None:
    """A signal after the command ended: nothing left to stop."""


@contextlib.contextmanager
def interrupts(restore: bool = True) -> Iterator[Callable[[], bool]]:
    """Turn :data:`SIGNALS` into :class:`KeyboardInterrupt` within the context.

    Yields a function that tells whether a signal came. On leaving, the previous handlers
    come back (``restore``, for a caller in the same process, e.g. a test) or every later
    signal is ignored (the command line's entry point, which exits next).
    """
    received: list[int] = []

    def stop(signum: int, _frame: FrameType | None) -> None:
        received.append(signum)
        raise KeyboardInterrupt(signal.Signals(signum).name)

    previous = {signum: signal.signal(signum, stop) for signum in SIGNALS}
    try:
        yield lambda: bool(received)
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler if restore else _late)
