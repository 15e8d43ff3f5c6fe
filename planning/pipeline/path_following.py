"""The last resort of a plan: follow the sampling planner's path itself, stopping at its corners.

The search's trajectories are splines through a few waypoints: smooth and fast, but they cut
the corners of the path they follow. In a passage barely wider than the clearance every
one of them may touch it, and the plan would end in "no solution" although RRT-Connect
found a clear path (a false negative). So when the seeding has no attempt left
(:meth:`~planning.pipeline.seeding.PathSeeding.after`), :func:`follow_path` times that path
as it is: straight joint-space segments between its vertices, at rest at each
(:func:`~planning.curves.stop_and_go.stop_and_go`), which sweep exactly the segments the
sampling planner checked. Slower than a spline, as the robot stops at every corner; still
jerk-limited, C3 and given the same certified verification as every trajectory.
"""

from __future__ import annotations

import time

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SplineFit
from planning.curves.stop_and_go import stop_and_go
from planning.pipeline.choose import Choice, Refusal, verify
from planning.pipeline.offered import Timing
from planning.pipeline.problem import Problem, with_planner
from planning.pipeline.settings import MAX_WAYPOINTS
from planning.search.waypoints import waypoints_along

FloatArray = NDArray[np.float64]


def follow_path(problem: Problem, path: FloatArray) -> tuple[Problem, Choice | Refusal]:
    """The stop-and-go trajectory along ``path`` ``(k, moving)``, verified, and its problem.

    The problem returned has as many waypoints as the path has corners (at most
    :data:`~planning.pipeline.settings.MAX_WAYPOINTS`): the candidate's fitness terms in the
    result are those of the corners. A scene's fixed duration is kept when the path can be
    followed within it, else the trajectory is as fast as the limits allow and reported as
    stretched.
    """
    started = time.perf_counter()
    vertices = problem.configurations(path)
    vertices[0], vertices[-1] = problem.q_start, problem.q_goal
    limits = problem.robot.limits
    trajectory = stop_and_go(
        vertices, limits.velocity, limits.acceleration, limits.jerk, torque=problem.dynamics
    )
    trajectory, stretched = problem.duration.held(trajectory)
    fit = SplineFit(
        trajectory=trajectory,
        targets=vertices,
        nodes=np.stack([vertices, *([np.zeros_like(vertices)] * 3)], axis=-1),
        settings=problem.solver.settings,
    )
    timing = Timing(trajectory, "stop_and_go", fit, stretched, time.perf_counter() - started)
    verification = verify(problem, trajectory, fit)
    if not verification.accepted:
        cause = "; ".join(verification.problems) or "its certified check fails"
        return problem, Refusal(f"following it vertex to vertex {cause}", verification.check)
    count = int(np.clip(len(path) - 2, 1, MAX_WAYPOINTS))
    counted = with_planner(problem, waypoints=count)
    x = waypoints_along(path, count, ck.path_weights(problem.robot)[problem.moving]).ravel()
    return counted, Choice(x, vertices, timing, verification, 1)
