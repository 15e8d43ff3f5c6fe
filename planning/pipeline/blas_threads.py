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
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import ParamSpec, TypeVar

from threadpoolctl import ThreadpoolController

P = ParamSpec("P")
R = TypeVar("R")


@functools.cache
def _controller() -> ThreadpoolController:
    """The process's thread pools, found once (numpy's and scipy's BLAS are loaded by then)."""
    return ThreadpoolController()


def one_blas_thread(function: Callable[P, R]) -> Callable[P, R]:
    """``function`` run with BLAS libraries limited to one thread (module docstring)."""

    @functools.wraps(function)
    def limited(*args: P.args, **kwargs: P.kwargs) -> R:
        with _controller().limit(limits=1, user_api="blas"):
            return function(*args, **kwargs)

    return limited
