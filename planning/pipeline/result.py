"""The pipeline's output: :class:`PlanResult`, immutable, with everything that produced it."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SplineFit
from planning.curves.trajectory import Trajectory
from planning.pipeline.choose import Choice
from planning.pipeline.metrics import Elapsed, Metrics, measure
from planning.pipeline.objective import Breakdown
from planning.pipeline.problem import Problem
from planning.pipeline.scene import Scene
from planning.search.optimizer import SearchResult

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class PlanResult:
    """A planned, verified trajectory with everything that produced it.

    Attributes:
        problem: the problem solved (scene, robot, collision world, objective).
        waypoints: ``(p + 2, nq)`` start, intermediate waypoints, goal [rad, m].
        trajectory: the timed septic spline.
        spline: the spline fit (on the nominal knots, before timing).
        time_scale: the trajectory's duration over the spline's nominal one (the uniform
            time scaling, unless the timing is ``fastest``).
        metrics: figures of the result.
        breakdown: the chosen candidate's fitness terms.
        optimiser: the search's run (history, population).
        verification: the certified continuous check of the trajectory.
    """

    problem: Problem = field(repr=False)
    waypoints: FloatArray
    trajectory: Trajectory
    spline: SplineFit = field(repr=False)
    time_scale: float
    metrics: Metrics
    breakdown: Breakdown = field(repr=False)
    optimiser: SearchResult = field(repr=False)
    verification: ck.CurveCheck = field(repr=False)

    @property
    def scene(self) -> Scene:
        """The scene planned."""
        return self.problem.scene

    @property
    def robot(self) -> ck.Robot:
        """The robot planned for."""
        return self.problem.robot

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint order of every array."""
        return self.problem.robot.joint_names


def assemble(problem: Problem, searched: SearchResult, choice: Choice, elapsed: Elapsed) -> PlanResult:
    """The result of a plan: the chosen candidate, its trajectory and its figures."""
    timing = choice.timing
    breakdown = problem.objective.breakdown(choice.x[None])
    return PlanResult(
        problem=problem,
        waypoints=choice.nodes,
        trajectory=timing.trajectory,
        spline=timing.fit,
        time_scale=timing.trajectory.duration / timing.fit.trajectory.duration,
        metrics=measure(problem.robot, choice, breakdown, searched, elapsed),
        breakdown=breakdown,
        optimiser=searched,
        verification=choice.verification.check,
    )
