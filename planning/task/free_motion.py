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
from planning.errors import CprPlanError, PlanningError
from planning.pipeline.deadline import Deadline
from planning.pipeline.planner import solve
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.pipeline.timing import FreeDuration
from planning.pipeline.verification import Requirements
from planning.task.held_orientation import HeldMotion, goal_on_constraint, hold_orientation
from planning.task.orientation import OrientationConstraint
from planning.task.orientation_projection import Projector

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
    turned = _goal_turned_onto(problem, constraint)
    if turned is not None:  # a tool position whose IK solution turns the tool off the constraint
        try:
            problem = free_problem(dataclasses.replace(scene, goal=turned), robot, threads, on_constraint)
        except (CprPlanError, ck.CprKinError) as exc:
            at_m = list(scene.goal.tcp or ())
            raise PlanningError(
                f"the motion's goal: the arm cannot hold '{robot.tcp_frame}' at {at_m} m in the constraint's "
                f"orientation about {list(constraint.axes)} ({exc}): move the goal, or allow a larger "
                "angle_rad"
            ) from None
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


def _goal_turned_onto(problem: Problem, constraint: OrientationConstraint) -> Target | None:
    """A ``tcp`` goal turned onto ``constraint``: the pose its IK solution takes there, or ``None``.

    A tool position leaves the tool's orientation to the IK, which may turn it off the
    constraint (a 6- or 7-joint arm's solutions turn it any way); the constraint's own
    orientation is the one meant. Where ``problem``'s goal is a ``tcp`` goal whose solution
    does not keep the constraint, on the tool frame or on a frame fixed to it (a gripper's
    link), it is moved the least onto it, the constrained frame held where it is
    (:meth:`~planning.task.orientation_projection.Projector.project`), and the tool's
    orientation there, with the goal's position, is the pose goal returned (solved and verified
    as every pose is: the frame fixed to the tool turns with it). ``None`` where the goal keeps
    the constraint, is no tool position, or the start breaks the constraint
    (:func:`hold_orientation` names it).

    Raises:
        PlanningError: the arm cannot turn the tool onto the constraint there, or the
            constrained frame does not move with the tool (a tool position leaves its
            orientation to the IK).
    """
    robot, goal = problem.robot, problem.scene.goal
    if goal.tcp is None:
        return None
    projector = Projector.from_start(robot, constraint, problem.q_start)
    frame, held = projector.frame, projector.constraint
    start_rad, goal_rad = projector.angles(np.array([problem.q_start, problem.q_goal]))
    if start_rad > held.angle_rad or goal_rad <= held.angle_rad:  # a start that breaks it is the error
        return None
    if not robot.fixed_together(frame, robot.tcp_frame):
        raise PlanningError(
            f"the motion's goal: the IK solution of its tool position {list(goal.tcp)} m holds '{frame}' "
            f"{goal_rad:.4g} rad from the constraint's orientation about {list(held.axes)} (allowed "
            f"{held.angle_rad:.4g} rad), and '{frame}' does not move with the tool frame "
            f"'{robot.tcp_frame}', so no tool orientation turns it: give the goal as joint values (q) that "
            "keep the constraint, or constrain the tool frame"
        )
    q, angle = projector.project(problem.q_goal, keep_position=True)
    if angle > projector.aim_rad:
        raise PlanningError(
            f"the motion's goal: the arm cannot turn '{frame}' onto the constraint's orientation about "
            f"{list(held.axes)} with the tool at {list(goal.tcp)} m (turned the least, it comes "
            f"{angle:.4g} rad from it; allowed {held.angle_rad:.4g} rad): move the goal, or allow a larger "
            "angle_rad"
        )
    rotation = ck.frame_poses(robot, q[None], robot.tcp_frame)[0][:3, :3]
    return Target(
        pose=(tuple(goal.tcp), tuple(map(tuple, rotation.tolist()))),
        tolerance_m=goal.tolerance_m,
        tolerance_rad=goal.tolerance_rad,
    )


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
