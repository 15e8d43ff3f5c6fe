"""Whether the tool line a task draws next walks from a configuration: what chooses the move's goal.

A pose has several IK solutions, and from some the tool line that follows breaks where from
others it walks: the nearest the arm reaches soonest may lie where the line meets a joint limit
or a singularity a few centimetres on, where another elbow or wrist branch carries it through.
So a move to a ``tcp`` or ``pose`` goal followed by a line (waits between them change nothing)
prefers the goal's IK solutions from which the line walks to its end, clear of the margins
(:func:`cpr_kin.solve_ik`'s ``prefer``): the soonest of those where there is one, else the
soonest as before (the line then says where it breaks). The line's joint path from a solution
costs milliseconds (:func:`~planning.task.line_motion.line_path`); where the soonest solution's
line walks, the goal is the one it was without the line.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.errors import ToolLineBrokenError
from planning.pipeline.verification import Requirements
from planning.task.line_motion import first_blocked, line_path
from planning.task.segments import Segment, Wait
from planning.task.tool_line import ToolLine

FloatArray = NDArray[np.float64]


def line_after(segments: Sequence[Segment], index: int) -> ToolLine | None:
    """The tool line the task draws right after segment ``index`` (waits between), or ``None``."""
    for segment in segments[index + 1 :]:
        if not isinstance(segment, Wait):
            return segment if isinstance(segment, ToolLine) else None
    return None


def line_walks(
    world: ck.CollisionWorld, line: ToolLine, required: Requirements
) -> Callable[[FloatArray], bool]:
    """A test of a configuration: ``line`` walks from it to its end, within ``required``'s margins."""
    robot = world.robot

    def walks(q: FloatArray) -> bool:
        try:
            path = line_path(robot, q, line)
        except ToolLineBrokenError:
            return False
        return first_blocked(world, path.samples, required) is None

    return walks
