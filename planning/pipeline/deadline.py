"""When a plan must stop: its planner's ``time_limit_s`` counted from the search's start.

The problem is built first (the robot loaded, start and goal solved and checked), as MoveIt
loads its robot before the clock of ``allowed_planning_time`` runs.

A plan's stages ask :meth:`Deadline.passed` where they can stop with what they have:
RRT-Connect between samples (it returns no path), the firefly between iterations and the
CMA-ES refinement between generations (each returns its best so far), a caller's own
optimiser through its objective (:mod:`planning.pipeline.search`), the choice between
the timings it verifies (:mod:`planning.pipeline.choose`: past the limit, none after one
that failed), the planner between attempts (failing those, it follows the sampling
planner's path as its last resort, then stops), and the last resort itself (past the limit
the plan stops without it). So a plan ends after its limit by what its last stages take to
finish: the stage under way when it passed and at most one timing and certified check, of
the best candidate or of the followed path. A certified check may take seconds (a 7-joint
arm among shelves, on its exact meshes): one still under way at :attr:`Deadline.cut_at_s`,
the limit plus :func:`overrun_s` of it, is stopped there (:meth:`Deadline.cut`), its curve
not certified. A plan therefore ends by its limit plus that overrun, give or take a piece of
a check's work (:data:`cpr_kin.collision.decisive.CHUNK_ROWS` configurations).

The limit's clock (:func:`clock_s`) stops while numba compiles kernels
(:func:`cpr_kin.common.compiled.compile_seconds`): the first run on a machine compiles them, for
seconds a plan has no use of, and a limit that counted them would stop that plan where the
next one, its kernels on disk, succeeds.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

from cpr_kin.common.compiled import compile_seconds

OVERRUN_SHARE = 0.25
"""The share of a time limit that the work under way when it passes may still take (:func:`overrun_s`)."""
MIN_OVERRUN_S = 1.0
"""The least time [s] the work under way when a limit passes may still take: the check of one
timing on a generated scene takes milliseconds, of a long trajectory on exact meshes a second."""


def clock_s() -> float:
    """The clock a time limit runs on [s]: ``time.perf_counter``, less the time numba spent compiling."""
    return time.perf_counter() - compile_seconds()


def overrun_s(limit_s: float) -> float:
    """How long past ``limit_s`` [s] a certified check under way may go on [s].

    The larger of :data:`OVERRUN_SHARE` of the limit and :data:`MIN_OVERRUN_S`.
    """
    return max(OVERRUN_SHARE * limit_s, MIN_OVERRUN_S)


@dataclass(frozen=True)
class Deadline:
    """A point on the :func:`clock_s` clock [s]; ``inf``: never.

    Attributes:
        at_s: the clock's reading at which time is up [s].
        limit_s: the limit it was set from [s] (``None``: none), for messages.
        cut_at_s: the clock's reading at which a certified check still under way is stopped [s].
        feasible_at_s: the clock's reading at which time is up for a search that holds a
            feasible candidate [s] (``None``: :attr:`at_s`). A share of a plan's limit (the
            hulls', :mod:`planning.pipeline.hulls_first`) bounds how long a search looks for
            one; a search that found one refines it on to the plan's own deadline.
    """

    at_s: float = math.inf
    limit_s: float | None = None
    cut_at_s: float = math.inf
    feasible_at_s: float | None = None

    @classmethod
    def after(cls, limit_s: float | None, started_s: float) -> Deadline:
        """The deadline ``limit_s`` [s] after ``time.perf_counter`` read ``started_s`` [s] (``None``: never).

        Its checks are cut :func:`overrun_s` later. The time numba spends compiling from now on
        is not counted (:func:`clock_s`).
        """
        if limit_s is None:
            return cls()
        start_s = started_s - compile_seconds()
        return cls(start_s + limit_s, limit_s, start_s + limit_s + overrun_s(limit_s))

    def passed(self, feasible: bool = False) -> bool:
        """Whether time is up; ``feasible``: for a search that holds a feasible candidate.

        Such a search runs to :attr:`feasible_at_s` where it is set.
        """
        at_s = self.feasible_at_s if feasible and self.feasible_at_s is not None else self.at_s
        return at_s != math.inf and clock_s() >= at_s

    @property
    def stop(self) -> Callable[[], bool] | None:
        """:meth:`cut`, for a certified check to ask; ``None`` where nothing is cut (no limit)."""
        return None if self.cut_at_s == math.inf else self.cut

    def cut(self) -> bool:
        """Whether a certified check still under way must stop (a :data:`cpr_kin.collision.decisive.Stop`)."""
        return self.cut_at_s != math.inf and clock_s() >= self.cut_at_s

    def reason(self) -> str:
        """Why a plan stopped, the time it took on the limit's clock: for a "no solution" message."""
        elapsed_s = clock_s() - (self.at_s - (self.limit_s or 0.0))
        return (
            f"stopped after {elapsed_s:.3g} s by the time limit time_limit_s = {self.limit_s:g} s "
            "(raise it, or leave it unset for no limit)"
        )
