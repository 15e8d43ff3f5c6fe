"""The robot package's notices on a terminal: what ``cpr-plan`` and its batch workers show on stderr.

``cpr_kin`` says at ``INFO`` what keeps a user waiting (that it compiles its kernels, a first run's
tens of seconds: :mod:`cpr_kin.common.compiled`); a library leaves it to its user's logging. The
command line shows it to someone at a terminal, a line on stderr, and adds nothing to a pipe.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Iterator


@contextlib.contextmanager
def library_notices(label: str) -> Iterator[None]:
    """Within: what the robot package says at ``INFO`` or above (that it compiles its kernels) on stderr.

    Each notice is one line, ``label: notice``, for someone who waits at a terminal: where
    stderr is not one (a pipe, a file), nothing is added to it. The logger's own settings come
    back on exit.
    """
    if not sys.stderr.isatty():
        yield
        return
    import logging  # only for a terminal's notices: a new process's start-up otherwise

    log = logging.getLogger("cpr_kin")
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter(f"{label}: %(message)s"))
    level, propagate = log.level, log.propagate
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    log.propagate = False
    try:
        yield
    finally:
        log.removeHandler(handler)
        log.setLevel(level)
        log.propagate = propagate
