"""Timing the search's chosen path: the scene's fixed duration, or as fast as the limits allow.

- **Fixed duration** (the paper case): the spline on the scene's knots, stretched uniformly
  (and reported) only if it would break a velocity, acceleration or jerk limit.
- **Free duration**: two timings of the geometric path (the spline through the candidate's
  nodes that the fitness checked), the shorter offered first:

  - *fastest*: :func:`planning.curves.path_timing.time_path`;
  - *uniform*: what the planner did before, the spline on its nominal knots scaled until its
    worst peak meets a limit.

  The planner verifies them in that order, so a trajectory is never longer than the uniform
  timing of its path, and the fastest one is used whenever it passes the certified check
  (it may cut the path's corners by a few millimetres, see :mod:`planning.curves.path_timing`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from planning.curves.path_timing import time_path
from planning.curves.spline import SplineFit
from planning.curves.trajectory import Trajectory
from planning.problem import Problem

FloatArray = NDArray[np.float64]
Method = Literal["fixed", "fastest", "uniform"]


@dataclass(frozen=True)
class Timing:
    """One timing of a candidate's path.

    Attributes:
        trajectory: the timed trajectory.
        method: ``fixed`` (the scene's duration), ``fastest`` or ``uniform`` (module docstring).
        fit: the spline through the nodes that was timed (before timing).
        stretched: a fixed duration broke a limit and was stretched.
        time_s: wall time of computing it [s].
    """

    trajectory: Trajectory
    method: Method
    fit: SplineFit
    stretched: bool
    time_s: float


def uniform_scale(fit: SplineFit, problem: Problem) -> float:
    """The factor that stretches ``fit`` uniformly until its worst peak meets a limit."""
    limits = problem.robot.limits
    return fit.trajectory.time_scale_for_limits(limits.velocity, limits.acceleration, limits.jerk)


def timings(problem: Problem, nodes: FloatArray) -> list[Timing]:
    """The timings of a candidate's ``nodes`` ``(p + 2, nq)`` to verify, in order of preference."""
    scene, limits = problem.scene, problem.robot.limits
    started = time.perf_counter()
    fit = problem.solver.solve(nodes)
    if scene.duration is not None:  # the knots are the scene's: stretch only to meet a limit
        scale = uniform_scale(fit, problem)
        trajectory = fit.trajectory.time_scaled(max(scale, 1.0))
        return [Timing(trajectory, "fixed", fit, scale > 1.0, time.perf_counter() - started)]
    fastest = time_path(fit.trajectory, limits.velocity, limits.acceleration, limits.jerk)
    middle = time.perf_counter()
    uniform = fit.trajectory.time_scaled(uniform_scale(fit, problem))
    found = [
        Timing(fastest, "fastest", fit, False, middle - started),
        Timing(uniform, "uniform", fit, False, time.perf_counter() - middle),
    ]
    return sorted(found, key=lambda timing: timing.trajectory.duration)
