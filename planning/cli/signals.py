"""``Ctrl-C`` and ``SIGTERM`` as one interrupt, wherever it strikes.

While a command runs, both signals raise :class:`KeyboardInterrupt` (also when a shell
started the command in the background with ``SIGINT`` ignored) and are recorded: an
interrupt that surfaces as another exception (a compiled function reports it as a
``SystemError``) is still an interrupt (:func:`planning.outcome.interruption`), and one that
something swallowed is raised again before anything is written (:func:`checkpoint`). When the
command is over, a late signal is ignored: the process is exiting with its own code, and a
traceback would only hide it.
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Callable, Iterator
from types import FrameType

SIGNALS = (signal.SIGINT, signal.SIGTERM)

_received: list[int] = []
"""The signals the active :func:`interrupts` context received (process-wide, as handlers are)."""


def _late(_signum: int, _frame: FrameType | None) -> None:
    """A signal after the command ended: nothing left to stop."""


@contextlib.contextmanager
def interrupts(restore: bool = True) -> Iterator[Callable[[], bool]]:
    """Turn :data:`SIGNALS` into :class:`KeyboardInterrupt` within the context.

    Yields a function that tells whether a signal came. On leaving, the previous handlers
    come back (``restore``, for a caller in the same process, e.g. a test) or every later
    signal is ignored (the command line's entry point, which exits next).
    """
    _received.clear()

    def stop(signum: int, _frame: FrameType | None) -> None:
        _received.append(signum)
        raise KeyboardInterrupt(signal.Signals(signum).name)

    previous = {signum: signal.signal(signum, stop) for signum in SIGNALS}
    try:
        yield lambda: bool(_received)
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, handler if restore else _late)


def checkpoint() -> None:
    """Raise the interrupt again if a signal came within :func:`interrupts` and was swallowed.

    The handler raises at once, but the code it strikes may swallow the exception: a signal
    during an import of a compiled extension (``lxml``'s initialisation) was lost, and the
    command went on to write its files. A command calls this before it publishes anything.
    """
    if _received:
        raise KeyboardInterrupt(signal.Signals(_received[0]).name)
