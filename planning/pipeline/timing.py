"""Timing the search's chosen path: the scene's fixed duration, or as fast as the limits allow.

A scene either fixes the duration or leaves it free; the choice is made once, when the
problem is built (:func:`duration_rule`), and the rule object answers every question that
depends on it:

- :class:`FixedDuration` (the paper case): the spline on the scene's knots is the
  trajectory; its velocity, acceleration and jerk limits bind every candidate in the search,
  and the chosen one is stretched uniformly (and reported) only if its exact extrema still
  break a limit. A duration shorter than the least time the joint limits allow from start to
  goal is refused up front (:meth:`FixedDuration.check_reachable`).
- :class:`FreeDuration`: two timings of the geometric path (the spline through the
  candidate's nodes that the fitness checked), the shorter offered first: *fastest*
  (:func:`planning.curves.path_timing.time_path`) and *uniform* (the spline on its nominal
  knots scaled until its worst peak meets a limit). The planner verifies them in that order,
  so a trajectory is never longer than the uniform timing of its path, which is computed only
  when a sampled lower bound of its duration does not show the fastest one shorter, or once
  the fastest one has failed (:class:`~planning.pipeline.offered.Offered`). Once a fastest
  timing has failed the certified check, *narrowed* timings (:meth:`FreeDuration.narrowed`)
  try the fastest timing under lowered acceleration limits: the jerk filter's window is
  ``a / j``, a lower acceleration narrows it, and the corners it cuts shrink with it, while
  the velocity limit still holds the cruise.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Protocol

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.rest_to_rest import trapezoid_time
from planning.curves.path_timing import limits_time_scale, time_path
from planning.curves.spline import SepticSplineSolver, SplineFit
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.pipeline.offered import Method, Offered, Timing

if TYPE_CHECKING:
    import cpr_kin as ck

FloatArray = NDArray[np.float64]


class TimedProblem(Protocol):
    """What a timing asks of the problem it times (a :class:`~planning.pipeline.problem.Problem` is one)."""

    @property
    def solver(self) -> SepticSplineSolver:
        """The spline solver through a candidate's nodes."""
        ...

    @property
    def robot(self) -> ck.Robot:
        """The robot, whose joint limits bind the timing."""
        ...

    @property
    def dynamics(self) -> ck.Dynamics:
        """The robot's torques with the scene's payload, and their limits."""
        ...

    @property
    def duration(self) -> DurationRule:
        """Its duration rule (fixed or free)."""
        ...


SAMPLES_PER_SEGMENT = 16
"""Samples per spline segment of :func:`least_uniform_scale`."""


def uniform_scale(fit: SplineFit, problem: TimedProblem) -> float:
    """The factor that stretches ``fit`` uniformly until its worst peak meets a limit (torques too)."""
    limits = problem.robot.limits
    kinematic = np.stack([limits.velocity, limits.acceleration, limits.jerk])
    return limits_time_scale(fit.trajectory, kinematic, problem.dynamics)


def least_uniform_scale(fit: SplineFit, problem: TimedProblem) -> float:
    """A lower bound of :func:`uniform_scale`, from the kinematic peaks at samples of ``fit``.

    Samples' peaks are within the exact extrema and torques only raise the scale;
    :data:`SAMPLES_PER_SEGMENT` a segment come within a fraction of a per cent of it.
    """
    limits, trajectory = problem.robot.limits, fit.trajectory
    times = np.linspace(
        trajectory.knots[0], trajectory.knots[-1], SAMPLES_PER_SEGMENT * trajectory.n_segments + 1
    )
    ratios = [
        float(np.max(np.abs(trajectory(times, r)) / limit)) ** (1.0 / r)
        for r, limit in enumerate((limits.velocity, limits.acceleration, limits.jerk), start=1)
    ]
    return float(max(ratios))


class DurationRule(Protocol):
    """What depends on whether the scene fixes the duration (module docstring)."""

    @property
    def limits_bind_candidates(self) -> bool:
        """The search's knots are the trajectory's: the limits apply to every candidate."""
        ...

    @property
    def search_torque(self) -> ck.Dynamics | None:
        """The torques the search's duration estimate keeps (``None``: they do not bind)."""
        ...

    @property
    def still_method(self) -> Method:
        """How a trajectory that stands still is reported."""
        ...

    def nominal_duration(self, segments: int) -> float:
        """Duration of the search's spline on ``segments`` uniform segments [s]."""
        ...

    def still_duration(self, ipo_s: float) -> float:
        """Duration of a trajectory that stands still [s]."""
        ...

    def timings(self, problem: TimedProblem, nodes: FloatArray) -> Offered:
        """The timings of a candidate's ``nodes`` ``(p + 2, nq)`` to verify, in order of preference."""
        ...

    def held(self, trajectory: Trajectory) -> tuple[Trajectory, bool]:
        """A trajectory timed as fast as the limits allow, held to the rule, and whether it was stretched."""
        ...

    def narrowed(self, problem: TimedProblem, offered: Offered, share: float) -> Timing | None:
        """The path of ``offered`` timed under ``share`` of the acceleration limits, if that helps."""
        ...


@dataclass(frozen=True)
class FixedDuration:
    """The scene's duration: the search's knots are the trajectory's (module docstring).

    Attributes:
        seconds: the duration [s].
    """

    seconds: float
    limits_bind_candidates: bool = True
    still_method: Method = "fixed"
    search_torque: None = None

    def nominal_duration(self, segments: int) -> float:  # noqa: D102 - the protocol's
        return self.seconds

    def still_duration(self, ipo_s: float) -> float:  # noqa: D102
        return self.seconds

    def check_reachable(
        self, robot: ck.Robot, q_start: FloatArray, q_goal: FloatArray, rest_ends: bool
    ) -> None:
        """Refuse a duration shorter than the least time the limits allow from start to goal.

        At rest at both ends, a joint that moves ``d`` needs at least the trapezoid time
        under its velocity and acceleration limits; with free end velocities (natural
        ends), at least ``d / v``. Every path through waypoints takes at least as long.

        Raises:
            PlanningError: naming the duration, the least time and the joint that needs it.
        """
        limits = robot.limits
        distance = np.abs(q_goal - q_start)
        v, a = limits.velocity, limits.acceleration
        least = trapezoid_time(distance, v, a) if rest_ends else distance / v
        j = int(np.argmax(least))
        if self.seconds < least[j]:
            name = limits.names[j]
            how = "at rest at both ends" if rest_ends else "at its velocity limit"
            raise PlanningError(
                f"duration = {self.seconds:g} s is shorter than the least time the joint limits allow from "
                f"start to goal: {least[j]:.3g} s (joint '{name}' moves {distance[j]:.3g} "
                f"{robot.joint_unit(name)} {how}); give at least {least[j]:.3g} s, or leave duration out "
                "for the fastest timing"
            )

    def timings(self, problem: TimedProblem, nodes: FloatArray) -> Offered:  # noqa: D102
        started = time.perf_counter()
        fit = problem.solver.solve(nodes)
        scale = uniform_scale(fit, problem)
        trajectory = fit.trajectory.time_scaled(max(scale, 1.0))
        return Offered(Timing(trajectory, "fixed", fit, scale > 1.0, time.perf_counter() - started))

    def narrowed(self, problem: TimedProblem, offered: Offered, share: float) -> Timing | None:  # noqa: D102
        return None

    def held(self, trajectory: Trajectory) -> tuple[Trajectory, bool]:
        """``trajectory`` slowed to the scene's duration; as it is if it needs longer (stretched)."""
        if trajectory.duration > self.seconds:
            return trajectory, True
        return trajectory.time_scaled(self.seconds / trajectory.duration), False


@dataclass(frozen=True)
class FreeDuration:
    """As fast as the limits allow along the path (module docstring).

    Attributes:
        search_torque: the robot's torques, when they bind on the straight path from start to
            goal (:func:`~planning.pipeline.torques.search_torque`): the search's duration
            estimate keeps them too.
        still_jerk: the trajectory ends still in jerk too, not only in velocity and
            acceleration, so that it joins another motion at rest C3 (a task's segments):
            only the fastest and narrowed timings (``time_path(still_jerk=True)``), no uniform
            one (the spline's own ends move in jerk).
    """

    limits_bind_candidates: bool = False
    still_method: Method = "fastest"
    search_torque: ck.Dynamics | None = None
    still_jerk: bool = False

    def nominal_duration(self, segments: int) -> float:  # noqa: D102 - the protocol's
        return float(segments)

    def still_duration(self, ipo_s: float) -> float:  # noqa: D102
        return ipo_s  # a trajectory needs a time interval; a controller executes nothing shorter

    def held(self, trajectory: Trajectory) -> tuple[Trajectory, bool]:  # noqa: D102 - the protocol's
        return trajectory, False

    def timings(self, problem: TimedProblem, nodes: FloatArray) -> Offered:
        """The fastest timing of ``nodes``' path, then the uniform one; the uniform one first if shorter.

        The uniform timing is computed at once only when the fastest one is not shorter than
        a lower bound of its duration (:func:`least_uniform_scale`); else when asked for.
        """
        started = time.perf_counter()
        fit = problem.solver.solve(nodes)
        trajectory = self._fastest(problem, fit, 1.0)
        fastest = Timing(trajectory, "fastest", fit, False, time.perf_counter() - started)
        if self.still_jerk:  # the spline's own ends move in jerk: no uniform timing
            return Offered(fastest)

        def uniform() -> Timing:
            begun = time.perf_counter()
            scaled = fit.trajectory.time_scaled(uniform_scale(fit, problem))
            return Timing(scaled, "uniform", fit, False, time.perf_counter() - begun)

        if trajectory.duration <= fit.trajectory.duration * least_uniform_scale(fit, problem):
            return Offered(fastest, lambda: [uniform()])
        first, *others = sorted([fastest, uniform()], key=lambda timing: timing.trajectory.duration)
        return Offered(first, lambda: others)

    def _fastest(self, problem: TimedProblem, fit: SplineFit, share: float) -> Trajectory:
        """``fit``'s path timed as fast as the limits allow, its acceleration limits at ``share``."""
        limits = problem.robot.limits
        acceleration = share * limits.acceleration
        return time_path(
            fit.trajectory,
            limits.velocity,
            acceleration,
            limits.jerk,
            torque=problem.dynamics,
            still_jerk=self.still_jerk,
        )

    def narrowed(self, problem: TimedProblem, offered: Offered, share: float) -> Timing | None:
        """The path of ``offered`` timed under ``share`` of the acceleration limits.

        ``None`` when it is not shorter than the path's uniform timing.
        """
        uniform = offered.of("uniform")
        reference = offered.of("fastest") if self.still_jerk else uniform
        if reference is None:
            return None
        fit, started = reference.fit, time.perf_counter()
        trajectory = self._fastest(problem, fit, share)
        if uniform is not None and trajectory.duration >= uniform.trajectory.duration:
            return None
        return Timing(trajectory, "narrowed", fit, False, time.perf_counter() - started)


def duration_rule(
    duration_s: float | None, search_torque: ck.Dynamics | None = None
) -> FixedDuration | FreeDuration:
    """The rule of a scene's ``duration``: fixed when given, free when ``None`` (with ``search_torque``)."""
    return FreeDuration(search_torque=search_torque) if duration_s is None else FixedDuration(duration_s)


def narrowed_timings(problem: TimedProblem, offered: Offered, shares: Sequence[float]) -> list[Timing]:
    """The narrowed timings of ``offered``'s path at the falling ``shares`` of the acceleration limits.

    Down to the first share not shorter than the uniform timing (a lower share is slower still,
    the timing being monotone in the limits to a few per cent); none for a fixed duration.
    """
    found = []
    for timing in (problem.duration.narrowed(problem, offered, share) for share in shares):
        if timing is None:
            break
        found.append(timing)
    return found
