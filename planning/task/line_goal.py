"""Whether the tool line a task draws next walks from a configuration: what chooses the move's goal.

A pose has several IK solutions, and from some the tool line that follows breaks where from
others it walks: the nearest the arm reaches soonest may lie where the line meets a joint limit
or a singularity a few centimetres on, where another elbow or wrist branch carries it through.
So a move to a ``tcp`` or ``pose`` goal followed by a line (waits between them change nothing)
prefers the goal's IK solutions from which the line walks to its end, clear of the margins
(:func:`cpr_kin.solve_ik`'s ``prefer``): the soonest of those where there is one, else the
soonest as before (the line then says where it breaks, and that it breaks from every solution
tried). The line's joint path from a solution costs milliseconds
(:func:`~planning.task.line_motion.line_path`); where the soonest solution's line walks, the
goal is the one it was without the line.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.errors import ToolLineBrokenError
from planning.pipeline.verification import Requirements
from planning.task.line_motion import first_blocked, line_path
from planning.task.segments import Segment, Wait
from planning.task.tool_line import ToolLine

FloatArray = NDArray[np.float64]


def line_after(segments: Sequence[Segment], index: int) -> int | None:
    """Where the tool line the task draws right after segment ``index`` is (waits between); ``None``."""
    for later in range(index + 1, len(segments)):
        if not isinstance(segments[later], Wait):
            return later if isinstance(segments[later], ToolLine) else None
    return None


@dataclass
class LineWalks:
    """A test of a configuration: ``line`` walks from it to its end, within ``required``'s margins.

    Counts the configurations it was asked about and those the line walks from: where it
    walks from none of a goal's solutions, the line's break says so
    (:meth:`from_no_goal`).
    """

    world: ck.CollisionWorld
    line: ToolLine
    required: Requirements
    asked: int = 0
    walked: int = 0

    def __call__(self, q: FloatArray) -> bool:
        """Whether the line walks from ``q`` to its end (:func:`~planning.task.line_motion.line_path`)."""
        self.asked += 1
        try:
            path = line_path(self.world.robot, q, self.line)
        except ToolLineBrokenError:
            return False
        if first_blocked(self.world, path.samples, self.required) is not None:
            return False
        self.walked += 1
        return True

    def from_no_goal(self, broken: ToolLineBrokenError) -> ToolLineBrokenError:
        """``broken``, saying that the line broke from every goal solution asked, where it did."""
        if self.walked or not self.asked:
            return broken
        tried = "the one IK solution" if self.asked == 1 else f"each of the {self.asked} IK solutions"
        return ToolLineBrokenError(
            f"{broken.reason}; it breaks from {tried} of the move's goal tried", broken.fraction
        )
