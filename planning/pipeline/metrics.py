"""The figures of a planned trajectory, and their one serialisation.

:meth:`Metrics.to_record` gives them under the keys of the trajectory file's ``metrics``
section (``docs/formats.md``); the trajectory file, ``report.md``, the batch's
``summary.csv`` and the CLI's summary all take them from there.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

import cpr_kin as ck
from planning.pipeline.choose import Choice
from planning.pipeline.objective import Breakdown
from planning.pipeline.torques import TorqueProfile
from planning.search.optimizer import SearchResult
from planning.utilisation import ORDERS, limit_usage

WALL_TIMES = ("planning_time_s", "optimiser_time_s", "timing_time_s")
"""The record's wall times: ``None`` in a file written without ``timings``."""


@dataclass(frozen=True)
class Metrics:
    """Figures of a planned trajectory.

    Attributes:
        duration_s: trajectory duration [s].
        fitness: objective value of the chosen waypoints.
        t_sol_s: PTP time through the chosen nodes (the paper's objective value) [s].
        w_sol: normalised accumulated joint motion of the executed path.
        min_clearance_m: certified lower bound of the clearance along the trajectory [m].
        sampled_min_clearance_m: smallest clearance at the verification samples [m].
        max_node_deviation: largest |y_i - f_i| of the spline [rad or m].
        jerk_min: per joint, smallest jerk [rad/s^3 or m/s^3].
        jerk_max: per joint, largest jerk.
        limit_utilisation: largest |velocity|, |acceleration|, |jerk| over the limit, per order.
        mean_limit_utilisation: the same usage (largest over the joints) averaged over time,
            per order (:mod:`planning.utilisation`).
        integrated_squared_jerk: per joint [rad^2/s^5 or m^2/s^5].
        planning_time_s: wall time of the plan, building the problem included [s].
        optimiser_time_s: wall time of the search [s].
        evaluations: objective evaluations.
        candidates_verified: candidates that went through the final verification.
        duration_stretched: the requested duration broke a limit and was stretched.
        certified_step_m: the certified check's step: the most robot motion between two of its
            checks [m] (the scene's ``verify_step_m``, or the finer step the plan needed, on
            the meshes or their hulls); ``cpr-plan check`` tries it where the scene's cannot certify.
        timing: how the trajectory was timed: ``fixed`` (the scene's duration), ``fastest``,
            ``narrowed`` or ``uniform`` (see :mod:`planning.pipeline.timing`).
        timing_time_s: wall time of that timing [s].
        torque_utilisation: per joint with a known effort limit, the largest |torque| over
            it (RNEA every millisecond, :mod:`planning.pipeline.torques`), the payload included.
    """

    duration_s: float
    fitness: float
    t_sol_s: float
    w_sol: float
    min_clearance_m: float
    sampled_min_clearance_m: float
    max_node_deviation: float
    jerk_min: dict[str, float]
    jerk_max: dict[str, float]
    limit_utilisation: dict[str, float]
    mean_limit_utilisation: dict[str, float]
    integrated_squared_jerk: dict[str, float]
    planning_time_s: float
    optimiser_time_s: float
    evaluations: int
    candidates_verified: int
    duration_stretched: bool
    certified_step_m: float
    timing: str = "fixed"
    timing_time_s: float = 0.0
    torque_utilisation: dict[str, float] = field(default_factory=dict)

    def to_record(self, timings: bool = True) -> dict[str, Any]:
        """The metrics as plain JSON types, under the trajectory file's keys.

        Wall times (:data:`WALL_TIMES`) are ``None`` unless ``timings``: a file that records
        none is the same, byte for byte, for the same scene and seed.
        """
        record = {
            "duration": self.duration_s,
            "min_clearance": self.min_clearance_m,
            "sampled_min_clearance": self.sampled_min_clearance_m,
            "max_node_deviation": self.max_node_deviation,
            "jerk_min": self.jerk_min,
            "jerk_max": self.jerk_max,
            "limit_utilisation": self.limit_utilisation,
            "mean_limit_utilisation": self.mean_limit_utilisation,
            "integrated_squared_jerk": self.integrated_squared_jerk,
            "fitness": self.fitness,
            "t_sol": self.t_sol_s,
            "w_sol": self.w_sol,
            "planning_time_s": self.planning_time_s,
            "optimiser_time_s": self.optimiser_time_s,
            "evaluations": self.evaluations,
            "candidates_verified": self.candidates_verified,
            "duration_stretched": self.duration_stretched,
            "certified_step": self.certified_step_m,
            "timing": self.timing,
            "timing_time_s": self.timing_time_s,
            "torque_utilisation": self.torque_utilisation,
        }
        return record if timings else {**record, **dict.fromkeys(WALL_TIMES)}


def torque_peaks(torques: TorqueProfile | None) -> dict[str, float]:
    """Peak ``|torque| / effort`` per joint with a known effort limit (none: no torques checked)."""
    if torques is None:
        return {}
    limited = np.isfinite(torques.effort)
    return {
        name: float(peak)
        for name, peak, known in zip(torques.joint_names, torques.peak_utilisation, limited, strict=True)
        if known
    }


class Elapsed(NamedTuple):
    """Wall times of a plan [s].

    Attributes:
        planning_s: the whole plan, building the problem included.
        search_s: from the start of solving to the end of the last search.
    """

    planning_s: float
    search_s: float


def measure(
    robot: ck.Robot, choice: Choice, breakdown: Breakdown, searched: SearchResult, elapsed: Elapsed
) -> Metrics:
    """The metrics of a verified trajectory.

    Args:
        robot: the robot (joint names, limits).
        choice: the verified candidate, its timing and its check.
        breakdown: the chosen candidate's fitness terms (one candidate).
        searched: the optimiser's run.
        elapsed: wall times of the plan.
    """
    timing, check = choice.timing, choice.verification.check
    trajectory = timing.trajectory
    limits = robot.limits
    names = robot.joint_names
    jerk = trajectory.extrema(3)
    utilisation = {
        kind: float(np.max(trajectory.extrema(r).peak / limit))
        for r, (kind, limit) in enumerate(
            (("velocity", limits.velocity), ("acceleration", limits.acceleration), ("jerk", limits.jerk)),
            start=1,
        )
    }
    return Metrics(
        duration_s=trajectory.duration,
        fitness=float(breakdown.fitness[0]),
        t_sol_s=float(breakdown.t_sol_s[0]),
        w_sol=float(breakdown.w_sol[0]),
        min_clearance_m=check.certified_min_m,
        sampled_min_clearance_m=check.sampled_min_m,
        max_node_deviation=timing.fit.max_node_deviation,
        jerk_min=dict(zip(names, map(float, jerk.minimum), strict=True)),
        jerk_max=dict(zip(names, map(float, jerk.maximum), strict=True)),
        limit_utilisation=utilisation,
        mean_limit_utilisation=dict(
            zip(ORDERS, map(float, limit_usage(trajectory, limits).mean()), strict=True)
        ),
        integrated_squared_jerk=dict(zip(names, map(float, trajectory.integrated_squared_jerk), strict=True)),
        planning_time_s=elapsed.planning_s,
        optimiser_time_s=elapsed.search_s,
        evaluations=searched.evaluations,
        candidates_verified=choice.candidates_timed,
        duration_stretched=timing.stretched,
        certified_step_m=check.step_m,
        timing=timing.method,
        timing_time_s=timing.time_s,
        torque_utilisation=torque_peaks(choice.verification.torques),
    )
