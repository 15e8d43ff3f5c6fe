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
the best candidate or of the followed path (on a 7-joint arm among shelves, on its exact
meshes, a certified check takes up to several seconds).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass


@dataclass(frozen=True)
class Deadline:
    """A point on the ``time.perf_counter`` clock [s]; ``inf``: never.

    Attributes:
        at_s: the clock's reading at which time is up [s].
        limit_s: the limit it was set from [s] (``None``: none), for messages.
    """

    at_s: float = math.inf
    limit_s: float | None = None

    @classmethod
    def after(cls, limit_s: float | None, started_s: float) -> Deadline:
        """The deadline ``limit_s`` [s] after the clock read ``started_s`` [s] (never when ``None``)."""
        return cls() if limit_s is None else cls(started_s + limit_s, limit_s)

    def passed(self) -> bool:
        """Whether time is up."""
        return self.at_s != math.inf and time.perf_counter() >= self.at_s

    def reason(self, elapsed_s: float) -> str:
        """Why a plan stopped at ``elapsed_s`` [s] of its ``limit_s``: for a "no solution" message."""
        return (
            f"stopped after {elapsed_s:.3g} s by the time limit time_limit_s = {self.limit_s:g} s "
            "(raise it, or leave it unset for no limit)"
        )
