"""A task: free motions, tool lines and waits, planned one after the other into one trajectory.

:func:`plan_task` starts at the scene's start and plans each segment from where the one
before ends: a :class:`Move` by the planner's search (to a joint, ``tcp`` or pose goal, the
scene's obstacles, margins and payload), a :class:`~planning.task.tool_line.ToolLine` by
:func:`~planning.task.line_motion.plan_line`, a :class:`Wait` standing still. Every segment
starts and ends at rest, still in jerk too (the free motions' timing is asked for it,
:class:`~planning.pipeline.timing.FreeDuration`'s ``still_jerk``), so the joined trajectory is
C3 at every junction; the whole is verified as every trajectory of the planner is. The scene's
own goal is neither planned to nor needed: the segments say where the robot goes.

Not yet (issue 71): junctions that do not stop, attach and detach, the scene file's ``task:``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.stop_and_go import joined
from planning.curves.trajectory import Trajectory
from planning.errors import NoSolutionError, PlanningError, TaskSegmentError
from planning.pipeline.planner import solve
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.pipeline.timing import FreeDuration
from planning.pipeline.verification import Requirements, Verification, verify_trajectory
from planning.task.line_motion import LineMotion, plan_line
from planning.task.tool_line import ToolLine
from planning.validation import number_in

FloatArray = NDArray[np.float64]

LONGEST_WAIT_S = 3600.0
"""The longest wait of a task [s]."""


@dataclass(frozen=True)
class Move:
    """A free motion to ``goal``, around the scene's obstacles (the planner's search).

    Attributes:
        goal: a joint, ``tcp`` or pose goal, as a scene's.
    """

    goal: Target


@dataclass(frozen=True)
class Wait:
    """Standing still for ``seconds`` [s] (a grasp closing, a part settling)."""

    seconds: float

    def __post_init__(self) -> None:
        number_in("wait seconds", self.seconds, 0.0, LONGEST_WAIT_S, "s", low_open=True)


Segment = Move | ToolLine | Wait


@dataclass(frozen=True)
class SegmentMotion:
    """One segment of a planned task.

    Attributes:
        kind: ``free``, ``line`` or ``wait``.
        t0: when it starts in the task's trajectory [s].
        t1: when it ends [s].
        line: the planned line, for a ``line``.
    """

    kind: str
    t0: float
    t1: float
    line: LineMotion | None = None


@dataclass(frozen=True)
class TaskMotion:
    """A planned task (:func:`plan_task`).

    Attributes:
        segments: each segment's kind and times, in order.
        trajectory: the whole motion, C3, at rest at each junction.
        verification: the planner's verification of the whole (clearance, C3, limits, torques).
    """

    segments: tuple[SegmentMotion, ...]
    trajectory: Trajectory
    verification: Verification


def plan_task(scene: Scene, segments: Sequence[Segment], robot: ck.Robot | None = None) -> TaskMotion:
    """The task's ``segments`` planned from the scene's start, joined and verified.

    Raises:
        PlanningError: no segment, a bad segment, or a segment's bad input (a goal inside a
            margin, a line of zero length), naming the segment.
        TaskSegmentError: a segment has no solution (a ``NoSolutionError``: exit 3), naming
            it, with its own error as ``cause`` (a free motion not found; a line that breaks,
            with its ``fraction``).
    """
    if not segments:
        raise PlanningError("a task needs at least one segment (a Move, a ToolLine or a Wait)")
    problem = build_problem(dataclasses.replace(scene, goal=scene.start), robot)  # its goal: not the task's
    required = Requirements.of(problem)
    q = problem.q_start
    pieces: list[tuple[str, Trajectory, LineMotion | None]] = []
    for index, segment in enumerate(segments):
        try:
            kind, trajectory, line = _planned(problem, required, q, segment)
        except (PlanningError, ck.CprKinError) as exc:
            raise PlanningError(f"task segment {index} ({type(segment).__name__}): {exc}") from exc
        except NoSolutionError as exc:
            raise TaskSegmentError(index, type(segment).__name__, exc) from exc
        pieces.append((kind, trajectory, line))
        q = trajectory(trajectory.knots[-1])
    whole = joined([trajectory for _, trajectory, _ in pieces])
    starts = np.cumsum([0.0] + [trajectory.duration for _, trajectory, _ in pieces])
    records = tuple(
        SegmentMotion(kind, float(t0), float(t1), line)
        for (kind, _, line), t0, t1 in zip(pieces, starts[:-1], starts[1:], strict=True)
    )
    return TaskMotion(records, whole, verify_trajectory(problem.world, whole, required))


def _planned(
    problem: Problem, required: Requirements, q: FloatArray, segment: Segment
) -> tuple[str, Trajectory, LineMotion | None]:
    """One segment from ``q``: its kind, its trajectory from time 0, and the line if it is one."""
    if isinstance(segment, ToolLine):
        line = plan_line(problem.world, q, segment, required)
        return "line", line.trajectory, line
    if isinstance(segment, Wait):
        coefficients = np.zeros((1, len(q), 8))
        coefficients[0, :, 0] = q
        return "wait", Trajectory(np.array([0.0, segment.seconds]), coefficients), None
    if isinstance(segment, Move):
        scene = dataclasses.replace(problem.scene, start=Target(q=tuple(q.tolist())), goal=segment.goal)
        moving = build_problem(scene, problem.robot)
        if not isinstance(moving.duration, FreeDuration):
            raise PlanningError(
                "a task's free motion is timed as fast as the limits allow: leave duration out"
            )
        still = dataclasses.replace(moving.duration, still_jerk=True)
        return "free", solve(dataclasses.replace(moving, duration=still)).trajectory, None
    raise PlanningError(f"a task segment is a Move, a ToolLine or a Wait, not a {type(segment).__name__}")
