"""The waypoint objective after Severin & Rossmann (2012), paper eq. 3-7.

A candidate is ``p`` intermediate waypoints of the moving joints (paper eq. 3), visited
between the fixed start and goal. Its terms:

- ``t_sol``: time of the point-to-point motion through start, waypoints and goal, each
  segment a synchronised rest-to-rest trapezoidal move under the joints' v/a limits;
- ``w_sol``: the joint motion accumulated over the IPO interpolation steps of the executed
  path (eq. 7), each joint normalised by its range;
- ``t_max``, ``w_max``: the same for the longest possible solution (every segment crossing
  every moving joint's full range); ``t_max`` includes one IPO so that every feasible value
  ``t_sol + (w_sol / w_max) IPO`` stays at or below it.

Fitness (lower is better), with the margin checked by coal on the executed path (the septic
spline through the nodes, or the paper's straight PTP lines), at ``fitness_samples``
configurations and against ``margin + verify_step_m``:

- ``paper``: feasible ``F = t_sol + (w_sol / w_max) IPO`` (eq. 4); effector only violates:
  ``2 t_max - F`` (eq. 5); links violate ("shoulder", with or without the effector), or a
  joint leaves its range: ``2 t_max + F`` (our reading of eq. 6).
- ``clearance`` (default): feasible as eq. 4, except that when the scene leaves the duration
  free, ``t_sol`` is replaced by how fast the path itself can be run (its phase-plane time
  plus what the jerk limit adds, :mod:`planning.curves.jerk_window`): the search then optimises the
  trajectory that is executed, not the paper's proxy of stopping at every waypoint;
  infeasible ``2 t_max + t_max (depth / required + excess)``, with ``depth`` the mean
  violation of the required clearance over the samples [m] and ``excess`` the sum of the
  other violations below, each relative to its bound.
  The margin is checked at every 4th sample first; the rest only where it can still make the
  candidate feasible (no violation so far); depth is the mean over the samples checked.
  Feasible always ranks ahead of infeasible.

Beyond the margin, a feasible candidate's spline must stay within the joint ranges, deviate
from its nodes by at most ``max_node_deviation`` (when set) and, when the scene fixes the duration,
keep velocity, acceleration and jerk within the limits at that duration (checked at the IPO
samples; the final timing uses exact extrema). The paper fitness ranks these violations
with eq. 6.

The paths themselves (samples, ``w_sol``, range, limit and deviation terms) are those of
:mod:`planning.path_terms`.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.ptp import ptp_time, trapezoid_time
from planning.curves.spline import SepticSplineSolver
from planning.path_terms import ExecutedPaths
from planning.scene import PlannerSettings

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@dataclass(frozen=True)
class Breakdown:
    """The fitness of a batch of candidates, term by term (all ``(S,)``).

    Attributes:
        fitness: the objective value.
        t_sol_s: PTP time through the candidate's nodes [s].
        duration_s: how fast the path can be run, with the duration free and the clearance
            fitness, for a feasible candidate (``nan`` otherwise: an infeasible candidate's
            fitness does not count it, so it is not estimated) [s].
        w_sol: normalised accumulated joint motion of the executed path.
        feasible: no margin violation and no joint beyond its limits.
        effector_violates: the wrist or tool comes closer than the required clearance (with
            the ``clearance`` fitness: is the closest group at a violating sample).
        links_violate: base, column, carriage or arm comes closer than the required
            clearance (likewise).
        depth_m: mean violation of the required clearance over the samples checked [m].
        overshoot: largest excursion beyond a joint limit, as a fraction of its range.
        limit_excess: largest |velocity|, |acceleration| or |jerk| over its limit, minus 1
            (0 when within limits or when the duration is free).
        node_deviation: largest spline node deviation [rad or m].
        min_clearance_m: smallest sampled clearance (``inf`` where every sample is clear of
            the required clearance: distances are computed only where it is violated).
    """

    fitness: FloatArray
    t_sol_s: FloatArray
    duration_s: FloatArray
    w_sol: FloatArray
    feasible: BoolArray
    effector_violates: BoolArray
    links_violate: BoolArray
    depth_m: FloatArray
    overshoot: FloatArray
    limit_excess: FloatArray
    node_deviation: FloatArray
    min_clearance_m: FloatArray


class WaypointObjective:
    """Batch fitness of waypoint candidates for one scene.

    Args:
        world: robot and obstacles.
        q_start: start configuration [rad, m].
        q_goal: goal configuration [rad, m].
        moving: indices of the joints the waypoints move.
        margin_m: safety margin [m].
        settings: planner settings (fitness kind, path kind, IPO, samples, buffer).
        solver: the septic spline solver on the trajectory's knots (``N = p + 1`` segments).
        timed: the knots are the final timing (the scene fixes the duration), so velocity,
            acceleration and jerk limits apply to candidates.
    """

    def __init__(
        self,
        world: ck.CollisionWorld,
        q_start: FloatArray,
        q_goal: FloatArray,
        moving: NDArray[np.intp],
        margin_m: float,
        settings: PlannerSettings,
        solver: SepticSplineSolver,
        timed: bool = False,
    ) -> None:
        robot = world.robot
        self.world = world
        self.q_start, self.q_goal = np.asarray(q_start, dtype=float), np.asarray(q_goal, dtype=float)
        self.moving = np.asarray(moving, dtype=np.intp)
        self.settings = settings
        self.solver = solver
        self.n_waypoints = settings.waypoints
        self.required_m = margin_m + settings.verify_step_m
        limits = robot.limits
        self.lower_q, self.upper_q = limits.lower, limits.upper
        self.v_max, self.a_max = limits.velocity, limits.acceleration
        self.timed = timed
        # with the duration free, the clearance fitness ranks by how fast a path can be run
        self.estimates_duration = not timed and settings.fitness == "clearance" and settings.path == "spline"
        self.paths = ExecutedPaths(limits, self.q_start, self.q_goal, self.moving, settings, solver, timed)
        segments = self.n_waypoints + 1
        self.lower = np.tile(limits.lower[self.moving], self.n_waypoints)
        self.upper = np.tile(limits.upper[self.moving], self.n_waypoints)
        longest = float(
            trapezoid_time(limits.range[self.moving], self.v_max[self.moving], self.a_max[self.moving]).max()
        )
        self.t_max = segments * longest + settings.ipo
        self.w_max = float(segments * self.moving.size)
        self._pair_group = np.array([ck.GROUPS.index(group) for _, _, group in world.pairs], dtype=np.intp)

    @property
    def dimension(self) -> int:
        """Length of a decision vector: waypoints x moving joints."""
        return int(self.lower.size)

    def nodes(self, x: FloatArray) -> FloatArray:
        """``(S, p + 2, nq)`` start, waypoints and goal of candidates ``x`` ``(S, p k)``."""
        x = np.atleast_2d(np.asarray(x, dtype=float))
        s = len(x)
        nodes = np.empty((s, self.n_waypoints + 2, self.q_start.size))
        nodes[:, 0], nodes[:, -1] = self.q_start, self.q_goal
        nodes[:, 1:-1] = self.q_start  # held joints keep the start's values
        nodes[:, 1:-1, self.moving] = x.reshape(s, self.n_waypoints, self.moving.size)
        return nodes

    def straight_line(self) -> FloatArray:
        """The decision vector whose waypoints lie evenly on the straight line from start to goal."""
        fractions = np.arange(1, self.n_waypoints + 1) / (self.n_waypoints + 1)
        points = self.q_start + fractions[:, None] * (self.q_goal - self.q_start)
        return np.asarray(points[:, self.moving].ravel())

    @cached_property
    def lower_bound(self) -> float:
        """About the least value a feasible candidate can have, obstacles ignored [s].

        With the duration estimated, the straight line's estimate: every path moves each
        joint at least as far, and the straight line comes within a few percent of the
        time-optimal motion. Otherwise the direct point-to-point time from start to goal:
        a segment's trapezoid time is subadditive in its length, so stopping at waypoints
        never takes less. The refinement's early stop counts only near it
        (:data:`~planning.search.refinement.NEAR_BOUND`).
        """
        if self.estimates_duration:
            samples = self.paths(self.nodes(self.straight_line())).samples
            return float(self.paths.durations(samples)[0])
        direct = np.stack([self.q_start, self.q_goal])
        return float(ptp_time(direct, self.v_max, self.a_max))

    def __call__(self, x: FloatArray) -> FloatArray:
        """``(S,)`` fitness of candidates ``x`` ``(S, p k)`` in joint units."""
        return self.breakdown(x).fitness

    def _clearance(self, samples: FloatArray, may_be_feasible: BoolArray) -> FloatArray:
        """``(S, K, 2)`` per-group clearance where it falls short of the required clearance.

        ``inf`` where a sample keeps the required clearance, ``nan`` where it was not checked.
        Staged: every 4th sample first, for every candidate; the others only for candidates
        clear there that ``may_be_feasible`` (no other violation), the only ones whose
        feasibility the remaining samples decide. An infeasible candidate so costs a
        quarter, its depth the mean over the coarse samples. Where coal's parallel yes/no
        test flags a sample, its distance is computed.
        """
        s, k, _ = samples.shape
        clearance = np.full((s, k, 2), np.nan)
        coarse = np.zeros(k, dtype=bool)
        coarse[::4] = True
        coarse[-1] = True
        self._fill(clearance, samples, np.arange(s), coarse)
        still_clear = ~(clearance[:, coarse] < self.required_m).any(axis=(1, 2))
        self._fill(clearance, samples, np.flatnonzero(still_clear & may_be_feasible), ~coarse)
        return clearance

    def _fill(
        self, clearance: FloatArray, samples: FloatArray, candidates: NDArray[np.intp], columns: BoolArray
    ) -> None:
        """Check ``samples[candidates][:, columns]`` and write the result into ``clearance``."""
        if candidates.size == 0 or not columns.any():
            return
        flat = samples[candidates][:, columns].reshape(-1, samples.shape[2])
        values = np.full((len(flat), 2), np.inf)
        flagged = np.flatnonzero(self.world.margin_violated(flat, self.required_m))
        if flagged.size:
            if self.settings.fitness == "paper":
                values[flagged] = self.world.clearance_batch(flat[flagged]).clearance_m
            else:  # one query per sample; the violation goes to the closest pair's group
                distance, pair = self.world.min_clearance_batch(flat[flagged], below_m=self.required_m)
                values[flagged, self._pair_group[pair]] = distance
        block = clearance[candidates]
        block[:, columns] = values.reshape(len(candidates), -1, 2)
        clearance[candidates] = block

    def breakdown(self, x: FloatArray) -> Breakdown:
        """The fitness of candidates ``x`` ``(S, p k)`` with all its terms."""
        nodes = self.nodes(x)
        t_sol = ptp_time(nodes, self.v_max, self.a_max)
        paths = self.paths(nodes)
        w_sol, excess, deviation = paths.w_sol, paths.limit_excess, paths.node_deviation
        bound = self.settings.max_node_deviation
        deviation_excess = (
            np.zeros_like(deviation) if bound is None else np.maximum(deviation / bound - 1.0, 0.0)
        )
        other = paths.overshoot + excess + deviation_excess
        clearance = self._clearance(np.clip(paths.samples, self.lower_q, self.upper_q), other <= 0.0)
        shortfall = np.maximum(self.required_m - clearance, 0.0)
        effector = np.asarray((clearance[:, :, 0] < self.required_m).any(axis=1))
        links = np.asarray((clearance[:, :, 1] < self.required_m).any(axis=1))
        worst = np.maximum(shortfall[:, :, 0], shortfall[:, :, 1])  # nan where a sample was not checked
        checked = ~np.isnan(worst)
        depth = np.where(checked, worst, 0.0).sum(axis=1) / checked.sum(axis=1)
        feasible = ~(effector | links) & (other <= 0.0)
        duration = np.full(len(t_sol), np.nan)
        time_s = t_sol
        if self.estimates_duration:  # only a feasible candidate's fitness counts its duration
            duration[feasible] = self.paths.durations(paths.samples[feasible])
            time_s = np.minimum(duration, self.t_max - self.settings.ipo)
        base = time_s + np.minimum(w_sol / self.w_max, 1.0) * self.settings.ipo
        if self.settings.fitness == "paper":
            fitness = np.where(
                feasible, base, np.where(links | (other > 0), 2 * self.t_max + base, 2 * self.t_max - base)
            )
        else:
            penalty = self.t_max * (depth / max(self.required_m, 1e-3) + other)
            fitness = np.where(feasible, base, 2 * self.t_max + penalty)
        return Breakdown(
            fitness=fitness,
            t_sol_s=t_sol,
            duration_s=duration,
            w_sol=w_sol,
            feasible=feasible,
            effector_violates=effector,
            links_violate=links,
            depth_m=depth,
            overshoot=paths.overshoot,
            limit_excess=excess,
            node_deviation=deviation,
            min_clearance_m=np.nanmin(clearance, axis=(1, 2)),
        )
