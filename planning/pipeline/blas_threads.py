"""One BLAS thread while a plan runs: its linear algebra is small, and coal's pool owns the cores.

A plan's matrix work is small (the refinement's covariance of some tens of dimensions, a
path's samples times its joints), too small for OpenBLAS's threads to pay; and the collision
checks between those calls run in Pinocchio's OpenMP pool, whose threads keep spinning on
the cores for a while after each batch. OpenBLAS's own threads, woken for the next product,
then wait for those cores: on a 2-core machine a 27-dimensional ``eigh`` took 1.2 ms inside
a plan of Alex's arm instead of 0.05 ms alone, and whole plans ran up to twice as long
(``docs/benchmarks.md``, stop 56). So :func:`one_blas_thread` holds BLAS libraries to one
thread for the call it wraps and gives the caller's setting back afterwards (threadpoolctl).
Results are the same to the bit.

A process that runs one command (``cpr-plan``) holds BLAS to one thread from its start
instead (:func:`one_thread_for_process`): OpenBLAS reads its thread count once, when NumPy
loads it, and threadpoolctl's search of the process's libraries for their pools (a walk over
every loaded library) is then not needed.
"""

from __future__ import annotations

import functools
import os
import sys
from collections.abc import Callable
from typing import TYPE_CHECKING, ParamSpec, TypeVar

if TYPE_CHECKING:
    from threadpoolctl import ThreadpoolController

P = ParamSpec("P")
R = TypeVar("R")

OPENBLAS_THREADS = "OPENBLAS_NUM_THREADS"
"""The variable OpenBLAS reads its thread count from when it loads."""

_set_at_start = False
"""Whether :func:`one_thread_for_process` set :data:`OPENBLAS_THREADS` before NumPy loaded."""


def one_thread_for_process() -> None:
    """Hold OpenBLAS to one thread for the whole process, if NumPy has not loaded it yet.

    For a process that runs one command and ends (its child processes inherit the setting);
    a library caller keeps its own threads. Too late, it does nothing: each plan is then
    limited on its own.
    """
    global _set_at_start
    if "numpy" not in sys.modules:
        os.environ[OPENBLAS_THREADS] = "1"
        _set_at_start = True


@functools.cache
def _whole_process_on_one_thread() -> bool:
    """Whether BLAS is NumPy's OpenBLAS held to one thread since the process started."""
    import numpy as np

    blas = np.__config__.CONFIG.get("Build Dependencies", {}).get("blas", {}).get("name", "")
    return _set_at_start and os.environ.get(OPENBLAS_THREADS) == "1" and "openblas" in str(blas).lower()


@functools.cache
def _controller() -> ThreadpoolController:
    """The process's thread pools, found once (numpy's and scipy's BLAS are loaded by then)."""
    from threadpoolctl import ThreadpoolController

    return ThreadpoolController()


def one_blas_thread(function: Callable[P, R]) -> Callable[P, R]:
    """``function`` run with BLAS libraries limited to one thread (module docstring)."""

    @functools.wraps(function)
    def limited(*args: P.args, **kwargs: P.kwargs) -> R:
        if _whole_process_on_one_thread():
            return function(*args, **kwargs)
        with _controller().limit(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return limited
