"""Ruckig's time-optimal jerk-limited duration: the lower bound of the timing benchmarks.

Any trajectory from rest at ``q_start`` to rest at ``q_goal`` within per-joint velocity,
acceleration and jerk limits lasts at least as long as the time-optimal one with no
obstacle at all, which Ruckig (``ruckig``, Berscheid and Kroeger 2021) computes exactly:
each joint's time-optimal profile, synchronised to the slowest.
"""

from __future__ import annotations

import numpy as np
import ruckig
from numpy.typing import ArrayLike

from planning.errors import PlanningError
from planning.pipeline.problem import Problem


def ruckig_duration(
    q_start: ArrayLike, q_goal: ArrayLike, velocity: ArrayLike, acceleration: ArrayLike, jerk: ArrayLike
) -> float:
    """The time-optimal rest-to-rest duration from ``q_start`` to ``q_goal`` [s].

    Args:
        q_start: ``(n,)`` start [rad, m].
        q_goal: ``(n,)`` goal [rad, m].
        velocity: ``(n,)`` limits [rad/s, m/s].
        acceleration: ``(n,)`` limits [rad/s^2, m/s^2].
        jerk: ``(n,)`` limits [rad/s^3, m/s^3].

    Raises:
        PlanningError: the shapes differ, a limit is not finite and positive, or Ruckig
            finds no trajectory.
    """
    names = ("q_start", "q_goal", "velocity", "acceleration", "jerk")
    rows = [np.asarray(x, dtype=float) for x in (q_start, q_goal, velocity, acceleration, jerk)]
    n = rows[0].size
    for name, row in zip(names, rows, strict=True):
        if row.shape != (n,):
            raise PlanningError(f"{name} has shape {row.shape}; expected ({n},) like q_start")
        if not np.all(np.isfinite(row)) or (name in names[2:] and not np.all(row > 0)):
            allowed = "finite and > 0" if name in names[2:] else "finite"
            raise PlanningError(f"{name} = {row.tolist()} must be {allowed}")
    request = ruckig.InputParameter(n)
    request.current_position, request.target_position = rows[0].tolist(), rows[1].tolist()
    request.max_velocity, request.max_acceleration, request.max_jerk = (row.tolist() for row in rows[2:])
    trajectory = ruckig.Trajectory(n)
    result = ruckig.Ruckig(n).calculate(request, trajectory)
    if result != ruckig.Result.Working:
        raise PlanningError(f"Ruckig found no trajectory ({result})")
    return float(trajectory.duration)


def free_space_bound(problem: Problem) -> float:
    """:func:`ruckig_duration` from ``problem``'s start to its goal under its robot's limits [s].

    No trajectory of the problem, whatever its obstacles, is shorter.
    """
    limits = problem.robot.limits
    return ruckig_duration(problem.q_start, problem.q_goal, limits.velocity, limits.acceleration, limits.jerk)
