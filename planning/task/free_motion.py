"""A task's free motion: the planner's search, timed to end still, bent onto an orientation constraint.

A free motion of a task starts and ends at rest, still in jerk too
(:class:`~planning.pipeline.timing.FreeDuration`'s ``still_jerk``), so that the segments join
C3. Under an :class:`~planning.task.orientation.OrientationConstraint` its path is bent onto
the constraint, or one is planned on it (:func:`~planning.task.held_orientation.hold_orientation`).
"""

from __future__ import annotations

import dataclasses
import functools
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.pipeline.deadline import Deadline
from planning.pipeline.planner import solve
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.timing import FreeDuration
from planning.pipeline.verification import Requirements
from planning.task.held_orientation import HeldMotion, goal_on_constraint, hold_orientation
from planning.task.orientation import OrientationConstraint

if TYPE_CHECKING:
    from planning.search.firefly import FireflyProgress

FloatArray = NDArray[np.float64]

FIXED_DURATION = (
    "the scene fixes duration = {seconds:g} s; a task times each of its motions as fast as the limits "
    "allow: leave the duration out (duration=None)"
)


@dataclass(frozen=True)
class FreeMotion:
    """A task's free motion (:func:`plan_free`).

    Attributes:
        trajectory: the motion from time 0, at rest at both ends.
        problem: the scene's problem (its margin), whose finer step may certify it.
        held: the bent motion, under a constraint.
    """

    trajectory: Trajectory
    problem: Problem
    held: HeldMotion | None = None


def plan_free(
    scene: Scene,
    robot: ck.Robot,
    constraint: OrientationConstraint | None,
    required: Requirements,
    progress: Callable[[FireflyProgress], None] | None = None,
    threads: int | None = None,
    goal_test: Callable[[FloatArray], bool] | None = None,
) -> FreeMotion:
    """The free motion from ``scene``'s start to its goal, keeping ``constraint`` if given.

    ``threads``: those of the parallel collision checks (default: one on 2 cores, two on more).
    ``goal_test``: a test of a ``tcp`` or ``pose`` goal's IK solutions (the line the task draws
    next walks from there, :mod:`planning.task.line_goal`): the soonest of those it passes is
    the goal where one does.

    Raises:
        PlanningError: bad input: a start or goal inside a margin, or that does not keep the
            constraint; a fixed duration.
        NoSolutionError: no motion found, or none that keeps the constraint (within the
            scene's ``time_limit_s``, where it sets one, for the search and the path on the
            constraint together).
    """
    if constraint is None:
        problem = free_problem(scene, robot, threads, None if goal_test is None else lambda _: goal_test)
        return FreeMotion(solve(problem, progress).trajectory, problem)
    on_constraint = functools.partial(_on_constraint, robot, constraint, goal_test)
    problem = free_problem(scene, robot, threads, on_constraint)
    deadline = Deadline.after(scene.planner.time_limit_s, time.perf_counter())  # the search's own clock
    free = solve(problem, progress).trajectory
    held = hold_orientation(problem.world, free, constraint, required, scene.planner.seed, deadline)
    return FreeMotion(held.trajectory, problem, held)


def _on_constraint(
    robot: ck.Robot,
    constraint: OrientationConstraint,
    goal_test: Callable[[FloatArray], bool] | None,
    q_start: FloatArray,
) -> Callable[[FloatArray], bool]:
    """From ``q_start``, a constrained move's goal test: on the constraint's way, then ``goal_test``.

    :func:`~planning.task.held_orientation.goal_on_constraint`'s test first.
    """
    on_constraint = goal_on_constraint(robot, constraint, q_start)
    if goal_test is None:
        return on_constraint
    return lambda q: on_constraint(q) and goal_test(q)


def free_problem(
    scene: Scene,
    robot: ck.Robot,
    threads: int | None = None,
    goal_test: Callable[[FloatArray], Callable[[FloatArray], bool]] | None = None,
) -> Problem:
    """The problem of a task's free motion: timed to end still in jerk too.

    ``threads``: its checks'; ``goal_test``: from the start's configuration, a test its goal
    passes where an IK solution does (:func:`~planning.pipeline.problem.build_problem`).

    Raises:
        PlanningError: the scene fixes a duration; a start or goal inside a margin.
    """
    problem = build_problem(scene, robot, threads, goal_test)
    if not isinstance(problem.duration, FreeDuration):
        raise PlanningError(FIXED_DURATION.format(seconds=scene.duration))
    return dataclasses.replace(problem, duration=dataclasses.replace(problem.duration, still_jerk=True))
