"""Numba's just-in-time compilation of the project's kernels, cached on disk.

Imported only where a kernel is compiled just in time (:mod:`cpr_kin.common.compiled`): a
process that runs the kernels compiled ahead of time (:mod:`cpr_kin.common.ahead`) never
imports numba. A compilation keeps a first run waiting with nothing to show for it; the first of
a process is said (:class:`FirstCompile`).
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from typing import Any

import numba
import numba.core.event

from cpr_kin.common.kernel_sources import forget_stale_kernels

_listening: list[FirstCompile] = []


class FirstCompile(numba.core.event.Listener):
    """Says ``message`` on ``log`` (``INFO``) at the first kernel numba compiles, once.

    Numba announces a compilation (its event ``numba:compile``) only where its disk cache holds
    no code for the kernel: a kernel loaded from the cache says nothing.
    """

    def __init__(self, log: logging.Logger, message: str) -> None:
        self.log, self.message, self.said = log, message, False

    def on_start(self, event: Any) -> None:
        """Say it, the first time."""
        if not self.said:
            self.said = True
            self.log.info(self.message)

    def on_end(self, event: Any) -> None:
        """Nothing: the start was said."""


def jit(function: Callable[..., Any], inline: bool, log: logging.Logger, message: str) -> Callable[..., Any]:
    """``function`` compiled in nopython mode, cached, releasing the GIL; inlined into callers if ``inline``.

    The first call of a process drops a source checkout's stale cache
    (:func:`~cpr_kin.common.kernel_sources.forget_stale_kernels`) and has the first compilation
    said on ``log`` (``message``).
    """
    if not _listening:
        forget_stale_kernels()
        _listening.append(FirstCompile(log, message))
        numba.core.event.register("numba:compile", _listening[0])  # type: ignore[no-untyped-call]
    options = {"inline": "always"} if inline else {}
    return numba.njit(cache=True, nogil=True, **options)(function)  # type: ignore[no-any-return, call-overload]
