"""The paths that candidate nodes make the robot execute: samples and their non-clearance terms.

For a batch of candidates' nodes (start, waypoints, goal), an executed-path rule fits the
path the robot runs, :class:`SplinePaths` (the septic spline through the nodes, the default)
or :class:`PtpPaths` (the paper's straight point-to-point lines; ``planner.path``, chosen
once by :func:`executed_paths`), and returns the configurations the fitness checks for
clearance and the terms that need no collision query:

- ``w_sol``: the joint motion accumulated over the IPO steps, each joint normalised by its
  range (paper eq. 7);
- ``overshoot``: the largest excursion beyond a joint range, as a fraction of the range;
- ``limit_excess``: when the knots are the final timing, the largest |velocity|,
  |acceleration| or |jerk| over its limit, minus 1 (sampled every IPO period, only for the
  joints and orders a Bernstein bound, :mod:`planning.curves.polynomial_bounds`, cannot
  certify);
- ``node_deviation``: the spline's largest |y_i - f_i|;

and, on request (:meth:`ExecutedPaths.durations`, for the candidates whose duration counts),
how fast each path can be run: the phase-plane time under the velocity and acceleration
limits on the check samples plus what the jerk limit adds
(:mod:`planning.curves.jerk_window`); the final timing comes within a few percent of it.

Only joints that move are fitted and sampled: the waypoint joints, and any other joint whose
goal differs from its start (it moves in the last segment). The rest keep their start value,
exactly, as the spline through constant nodes does.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.common.arrays import distinct_sorted
from planning.curves.averaged_path import averaged_samples
from planning.curves.jerk_window import sampled_path_durations
from planning.curves.path_timing import NODE_STEP_S, smoothing_limits
from planning.curves.piecewise_sampler import PiecewiseSampler
from planning.curves.polynomial_bounds import DerivativeBounds
from planning.curves.spline import SepticSplineSolver
from planning.curves.torque_estimate import sampled_torque_durations
from planning.curves.torque_limits import TorqueModel
from planning.curves.velocity_caps import ROUNDS, TOLERANCE
from planning.pipeline.motion import Motion
from planning.pipeline.settings import PlannerSettings

if TYPE_CHECKING:
    from planning.pipeline.timing import DurationRule

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class PathTerms:
    """The executed paths of ``S`` candidates.

    Attributes:
        samples: ``(S, K, nq)`` configurations to check for clearance [rad, m].
        w_sol: ``(S,)`` normalised accumulated joint motion.
        overshoot: ``(S,)`` largest excursion beyond a joint range, relative to the range.
        limit_excess: ``(S,)`` largest |v|, |a| or |j| over its limit, minus 1 (0 within).
        node_deviation: ``(S,)`` largest spline node deviation [rad or m].
    """

    samples: FloatArray
    w_sol: FloatArray
    overshoot: FloatArray
    limit_excess: FloatArray
    node_deviation: FloatArray


class PtpPaths:
    """The paper's executed path: straight joint-space lines from node to node.

    Its samples are evenly spaced on each segment; ``w_sol`` is the lines' joint motion. It
    has no overshoot, limit or deviation terms, and no duration estimate.

    Args:
        limits: the robot's joint limits.
        settings: planner settings (fitness samples).
    """

    estimates_duration = False

    def __init__(self, limits: ck.JointLimits, settings: PlannerSettings) -> None:
        self.range_q, self.samples = limits.range, settings.fitness_samples

    def __call__(self, nodes: FloatArray) -> PathTerms:
        """The executed paths through ``nodes`` ``(S, p + 2, nq)``."""
        s, n_nodes, nq = nodes.shape
        zeros = np.zeros(s)
        fraction = np.linspace(0.0, 1.0, max(2, self.samples // (n_nodes - 1)))
        steps = np.diff(nodes, axis=1)
        samples = nodes[:, :-1, None, :] + fraction[None, None, :, None] * steps[:, :, None, :]
        w_sol = (np.abs(steps) / self.range_q).sum(axis=(1, 2))
        return PathTerms(samples.reshape(s, -1, nq), w_sol, zeros, zeros, zeros)

    def durations(self, samples: FloatArray) -> FloatArray:
        """Not estimated for straight lines: the fitness ranks by the point-to-point time."""
        raise NotImplementedError("PtpPaths gives no duration estimate")

    def averaged(self, samples: FloatArray) -> FloatArray | None:
        """``None``: not foreseen for straight lines, whose fitness ranks by the point-to-point time."""
        return None


class SplinePaths:
    """Samples and terms of the septic splines through candidates' nodes.

    Args:
        limits: the robot's joint limits.
        motion: start, goal and moving joints (held joints keep the start's values).
        settings: planner settings (IPO, fitness samples).
        solver: the septic spline solver on the search's knots.
        timed: the knots are the final timing, so velocity, acceleration and jerk limits apply.
        torque: the robot's torques, which the duration estimate then keeps too; ``None``:
            kinematic limits only.
    """

    estimates_duration = True

    def __init__(
        self,
        limits: ck.JointLimits,
        motion: Motion,
        settings: PlannerSettings,
        solver: SepticSplineSolver,
        timed: bool,
        torque: TorqueModel | None = None,
    ) -> None:
        q_start, q_goal = motion.q_start, motion.q_goal
        self.q_start = q_start
        # joints the spline moves; the others stay at their start (= goal) value throughout
        self.fitted = distinct_sorted(motion.moving, np.flatnonzero(q_start != q_goal))
        self.settings, self.solver, self.timed, self.torque = settings, solver, timed, torque
        self.lower_q, self.upper_q, self.range_q = limits.lower, limits.upper, limits.range
        self._derivative_limits = (limits.velocity, limits.acceleration, limits.jerk)
        knots = solver.knots
        check_times = np.linspace(knots[0], knots[-1], settings.fitness_samples)
        self._check = PiecewiseSampler(knots, check_times, 8)
        self._last_step_powers = (knots[-1] - knots[-2]) ** np.arange(8.0)
        ipo_times = np.append(np.arange(knots[0], knots[-1], settings.ipo), knots[-1])
        self._ipo = PiecewiseSampler(knots, ipo_times, 8)
        self._ipo_derivatives = tuple(
            PiecewiseSampler(knots, ipo_times, 8, derivatives=r, first=r) for r in (1, 2, 3)
        )
        self._derivative_bounds = DerivativeBounds(knots, 8, (1, 2, 3))
        self._fitted_limits = (
            limits.velocity[self.fitted].copy(),
            limits.acceleration[self.fitted].copy(),
            limits.jerk[self.fitted].copy(),
        )
        self._window_s = float(np.max(limits.acceleration / limits.jerk))
        kinematic = np.stack([limits.velocity, limits.acceleration, limits.jerk])
        self._second_share = smoothing_limits(kinematic, NODE_STEP_S).second_share  # the timing's
        self._steps = np.empty((len(ipo_times) - 1, 0))  # reused buffer of IPO steps
        self._tiled: dict[int, tuple[FloatArray, ...]] = {}

    def __call__(self, nodes: FloatArray) -> PathTerms:
        """The executed paths through ``nodes`` ``(S, p + 2, nq)``."""
        s, n_nodes, nq = nodes.shape
        zeros = np.zeros(s)
        fitted, k = self.fitted, self.fitted.size
        columns = nodes[:, :, fitted].transpose(1, 0, 2).reshape(n_nodes, s * k)  # (nodes, S k)
        coefficients = self.solver.solve_batch(columns)
        samples = np.empty((s, self._check.count, nq))
        samples[...] = self.q_start  # held joints stay where they start (and end)
        samples[:, :, fitted] = self._check(coefficients)[0].reshape(-1, s, k).transpose(1, 0, 2)
        range_q, lower_q, upper_q, limits = self._tiles(s)
        positions = self._ipo(coefficients)[0]  # (IPO steps, S k): reduce over time first
        if self._steps.shape != (positions.shape[0] - 1, s * k):
            self._steps = np.empty((positions.shape[0] - 1, s * k))
        steps = np.subtract(positions[1:], positions[:-1], out=self._steps)
        w_sol = (np.abs(steps, out=steps).sum(axis=0) / range_q).reshape(s, k).sum(axis=1)
        beyond = np.maximum(positions.max(axis=0) - upper_q, lower_q - positions.min(axis=0)) / range_q
        overshoot = np.maximum(beyond.reshape(s, k).max(axis=1), 0.0)
        last = coefficients[-1] @ self._last_step_powers  # value at the end of the last segment
        node_values = np.concatenate([coefficients[:, :, 0], last[None]])
        deviation = np.abs(node_values - columns).max(axis=0).reshape(s, k).max(axis=1)
        excess = zeros
        if self.timed:  # largest |velocity|, |acceleration|, |jerk| relative to its limit
            utilisation = np.zeros(s * k)
            may_exceed = self._derivative_bounds(coefficients) > limits  # (3, S k)
            for r, sampler in enumerate(self._ipo_derivatives):
                unsure = np.flatnonzero(may_exceed[r])
                if unsure.size:  # the others stay within this limit: they add no excess
                    values = sampler(coefficients[:, unsure])[0]
                    peak = np.abs(values, out=values).max(axis=0) / limits[r, unsure]
                    utilisation[unsure] = np.maximum(utilisation[unsure], peak)
            excess = np.maximum(utilisation.reshape(s, k).max(axis=1) - 1.0, 0.0)
        return PathTerms(samples, w_sol, overshoot, excess, deviation)

    def durations(self, samples: FloatArray) -> FloatArray:
        """``(S,)`` how fast the paths of :attr:`PathTerms.samples` ``(S, K, nq)`` can be run [s].

        The jerk-limited phase-plane estimate of
        :func:`~planning.curves.jerk_window.sampled_path_durations` with the timing's window
        widenings (:data:`~planning.curves.velocity_caps.ROUNDS`,
        :data:`~planning.curves.velocity_caps.TOLERANCE`).
        """
        if self.torque is not None:
            limits = np.stack(self._fitted_limits)
            return sampled_torque_durations(
                samples, self.fitted, limits, self.torque, self._window_s, self._second_share
            )
        points = np.ascontiguousarray(samples[:, :, self.fitted])
        return sampled_path_durations(
            points, *self._fitted_limits, self._window_s, ROUNDS, TOLERANCE, self._second_share
        )

    def averaged(self, samples: FloatArray) -> FloatArray | None:
        """``(S, K, nq)`` the samples where the fastest timing's moving averages take them.

        :func:`~planning.curves.averaged_path.averaged_samples` on the profile of
        :meth:`durations` with the narrowest window, never widened: where the profile's jerk
        would widen it, the timing mostly keeps it and lowers the swinging joint's
        acceleration locally instead (:mod:`planning.curves.local_caps`; ``docs/tuning.md``).
        ``None`` where the estimate is torque-limited (its profile is not the one the
        kinematic timing averages).
        """
        if self.torque is not None:
            return None
        points = np.ascontiguousarray(samples[:, :, self.fitted])
        moved = samples.copy()
        moved[:, :, self.fitted] = averaged_samples(
            points, np.stack(self._fitted_limits), self._window_s, 0, TOLERANCE, self._second_share
        )
        return moved

    def _tiles(self, s: int) -> tuple[FloatArray, ...]:
        """Fitted joints' ranges, bounds and ``(3, S k)`` v/a/j limits, repeated for ``s`` candidates."""
        if s not in self._tiled:
            per_joint = (self.range_q, self.lower_q, self.upper_q)
            limits = np.stack([np.tile(limit[self.fitted], s) for limit in self._derivative_limits])
            self._tiled[s] = (*(np.tile(v[self.fitted], s) for v in per_joint), limits)
        return self._tiled[s]


ExecutedPaths = PtpPaths | SplinePaths


def executed_paths(
    limits: ck.JointLimits,
    motion: Motion,
    settings: PlannerSettings,
    solver: SepticSplineSolver,
    duration: DurationRule,
) -> ExecutedPaths:
    """The executed-path rule of ``settings.path``: ``spline`` (default) or ``ptp``.

    ``duration``: the scene's duration rule (whether the limits bind candidates, and the
    torques the duration estimate keeps).
    """
    if settings.path == "ptp":
        return PtpPaths(limits, settings)
    return SplinePaths(
        limits, motion, settings, solver, duration.limits_bind_candidates, duration.search_torque
    )
