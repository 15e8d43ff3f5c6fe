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

  - *narrowed* (:func:`narrowed_timings`, only once a fastest timing has failed the check):
    the fastest timing under acceleration limits lowered to :data:`NARROWED_ACCELERATION`
    of theirs. The jerk filter's window is ``a / j``: a lower acceleration limit narrows it,
    and the corners it cuts shrink with it, while the velocity limit still holds the
    cruise.
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
Method = Literal["fixed", "fastest", "narrowed", "uniform"]

NARROWED_ACCELERATION = (0.7, 0.5, 0.35)
"""Shares of the acceleration limits of the narrowed timings, tried in turn. Measured on the
200 scenes of ``scripts/bench_search.py`` (generator seeds 0 and 1) and the 50 of
``scripts/bench_timing.py``: four paths had every fastest timing of their three best
candidates refused by the check and ran at the uniform timing; with these fallbacks two
pass at 0.7 and two at 0.5, 17-47 % shorter than before. 0.35 is one more step before the
uniform timing; at 0.25 the paths above were longer than it."""


@dataclass(frozen=True)
class Timing:
    """One timing of a candidate's path.

    Attributes:
        trajectory: the timed trajectory.
        method: ``fixed`` (the scene's duration), ``fastest``, ``narrowed`` or ``uniform``
            (module docstring).
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


def narrowed_timing(problem: Problem, offered: list[Timing], share: float) -> Timing | None:
    """The path of ``offered`` (its :func:`timings`) timed under ``share`` of the acceleration limits.

    ``None`` for a fixed duration, or when it is not shorter than the path's uniform timing.
    """
    uniform = [timing for timing in offered if timing.method == "uniform"]
    if not uniform:
        return None
    limits, fit = problem.robot.limits, uniform[0].fit
    started = time.perf_counter()
    trajectory = time_path(fit.trajectory, limits.velocity, share * limits.acceleration, limits.jerk)
    if trajectory.duration >= uniform[0].trajectory.duration:
        return None
    return Timing(trajectory, "narrowed", fit, False, time.perf_counter() - started)


def narrowed_timings(problem: Problem, offered: list[Timing]) -> list[Timing]:
    """The narrowed timings of the path of ``offered`` at :data:`NARROWED_ACCELERATION`, fastest first.

    Those shorter than its uniform timing: the shares down to the first that is not (a lower
    share is slower still, as the timing is monotone in the limits to a few per cent).
    """
    found = []
    for share in NARROWED_ACCELERATION:
        timing = narrowed_timing(problem, offered, share)
        if timing is None:
            break
        found.append(timing)
    return found
