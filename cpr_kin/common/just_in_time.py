"""Numba's just-in-time compilation of the project's kernels, cached on disk.

Imported only where a kernel is compiled just in time (:mod:`cpr_kin.common.compiled`): a
process that runs the kernels compiled ahead of time (:mod:`cpr_kin.common.ahead`) never
imports numba. A compilation keeps a first run waiting with nothing to show for it; the first of
a process is said, and every compilation is timed (:class:`CompileWatch`), for a plan's time
limit to leave that time out (:func:`compile_seconds`).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from typing import Any

import numba
import numba.core.event

from cpr_kin.common.kernel_sources import forget_stale_kernels

_listening: list[CompileWatch] = []


class CompileWatch(numba.core.event.Listener):
    """Says ``message`` on ``log`` (``INFO``) at the first kernel numba compiles, once, and times them all.

    Numba announces a compilation (its event ``numba:compile``) only where its disk cache holds
    no code for the kernel: a kernel loaded from the cache says nothing and is not timed. A
    kernel's compilation compiles the kernels it calls within it: only the outermost is timed.

    Attributes:
        seconds: the wall time numba has spent compiling since the watch was registered [s].
    """

    def __init__(self, log: logging.Logger, message: str) -> None:
        self.log, self.message, self.said = log, message, False
        self.seconds = 0.0
        self._depth, self._began_s = 0, 0.0

    def on_start(self, event: Any) -> None:
        """Say it, the first time; start the clock at an outermost compilation."""
        if not self.said:
            self.said = True
            self.log.info(self.message)
        if self._depth == 0:
            self._began_s = time.perf_counter()
        self._depth += 1

    def on_end(self, event: Any) -> None:
        """Add an outermost compilation's time (not one begun before the watch was registered)."""
        if self._depth == 0:
            return
        self._depth -= 1
        if self._depth == 0:
            self.seconds += time.perf_counter() - self._began_s


def watch(log: logging.Logger, message: str) -> CompileWatch:
    """The process's :class:`CompileWatch`, registered with numba at the first call.

    The first call also drops a source checkout's stale cache
    (:func:`~cpr_kin.common.kernel_sources.forget_stale_kernels`).
    """
    if not _listening:
        forget_stale_kernels()
        _listening.append(CompileWatch(log, message))
        numba.core.event.register("numba:compile", _listening[0])  # type: ignore[no-untyped-call]
    return _listening[0]


def compile_seconds() -> float:
    """The wall time numba has spent compiling in this process since :func:`watch` was first called [s]."""
    return _listening[0].seconds if _listening else 0.0


def jit(function: Callable[..., Any], inline: bool, log: logging.Logger, message: str) -> Callable[..., Any]:
    """``function`` compiled in nopython mode, cached, releasing the GIL; inlined into callers if ``inline``.

    Its compilations are watched (:func:`watch`): the first of the process is said on ``log``
    (``message``), and each is timed.
    """
    watch(log, message)
    options = {"inline": "always"} if inline else {}
    return numba.njit(cache=True, nogil=True, **options)(function)  # type: ignore[no-any-return, call-overload]
