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

**Feasible** (:meth:`WaypointObjective.feasible`, the one place the rule is written): the
fitness is at most ``t_max``, which holds exactly when the executed path keeps
``margin + verify_step_m`` from every obstacle and ``self_margin + self_verify_step_m``
between the robot's own pairs at the ``fitness_samples`` samples (coal), stays within the
joint ranges, deviates from its nodes by at most ``max_node_deviation`` (when set), with a
gravity limit (:attr:`PathRules.gravity`) can be held still at every 4th sample and, when
the scene fixes the duration, keeps velocity, acceleration and jerk within the limits at
that duration (checked at the IPO samples; the final timing uses exact extrema). How
the terms become the fitness, feasible or not, is the fitness rule's
(:mod:`planning.pipeline.fitness`); the paths themselves are those of
:mod:`planning.pipeline.path_terms`.

The margin is checked at every 4th sample first; the rest only where it can still make the
candidate feasible (no violation so far); depth is the mean over the samples checked.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.common.rest_to_rest import trapezoid_time
from planning.curves.ptp import ptp_time
from planning.curves.spline import SepticSplineSolver
from planning.pipeline.fitness import FITNESS_RULES, Terms
from planning.pipeline.motion import Motion
from planning.pipeline.path_terms import executed_paths
from planning.pipeline.settings import PlannerSettings
from planning.pipeline.timing import DurationRule
from planning.pipeline.torques import GravityLimit

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
LINKS = ck.GROUPS.index("links")
FIRST_PASS_STRIDE = 4
"""The fitness's first pass checks every this many of a path's samples (``docs/tuning.md``)."""


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
        holding_excess: where the problem holds paths to a gravity limit, how far gravity's
            largest torque over its effort limit exceeds 1 on the path (0: every checked
            configuration can be held still).
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
    holding_excess: FloatArray
    min_clearance_m: FloatArray


@dataclass(frozen=True)
class PathRules:
    """What every configuration of a candidate's path keeps, besides the joint limits.

    Attributes:
        margin_m: the safety margin from every obstacle [m].
        self_margin_m: the self margin between the robot's own checked pairs [m].
        gravity: where gravity may exceed an effort limit, the rule that the motors hold
            every configuration of a path still (checked at every 4th sample and the last);
            ``None``: no such rule.
    """

    margin_m: float
    self_margin_m: float
    gravity: GravityLimit | None = None


class WaypointObjective:
    """Batch fitness of waypoint candidates for one scene.

    Args:
        world: robot and obstacles.
        motion: start, goal and the joints the waypoints move.
        rules: the margins every path keeps and, where gravity may bind, its gravity limit.
        settings: planner settings (fitness rule, path kind, IPO, samples, verification step).
        solver: the septic spline solver on the search's knots (``N = p + 1`` segments).
        duration: the scene's duration rule: with a fixed duration the knots are the final
            timing, so velocity, acceleration and jerk limits apply to candidates.
    """

    def __init__(
        self,
        world: ck.CollisionWorld,
        motion: Motion,
        rules: PathRules,
        settings: PlannerSettings,
        solver: SepticSplineSolver,
        duration: DurationRule,
    ) -> None:
        robot = world.robot
        self.world, self.motion = world, motion
        self.q_start, self.q_goal, self.moving = motion.q_start, motion.q_goal, motion.moving
        self.settings = settings
        self.solver = solver
        self.gravity = rules.gravity
        self.n_waypoints = settings.waypoints
        self.required_m = rules.margin_m + settings.verify_step_m
        self.required_self_m = rules.self_margin_m + settings.self_step_m
        limits = robot.limits
        self.lower_q, self.upper_q = limits.lower, limits.upper
        self.v_max, self.a_max = limits.velocity, limits.acceleration
        self.rule = FITNESS_RULES[settings.fitness]
        timed = duration.limits_bind_candidates
        self.paths = executed_paths(limits, motion, settings, solver, duration)
        # with the duration free, the clearance fitness ranks by how fast a path can be run
        self.estimates_duration = not timed and self.rule.ranks_by_duration and self.paths.estimates_duration
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
    def feasible_below(self) -> float:
        """The bound of feasible values: a candidate is feasible iff its fitness is at most this."""
        return self.t_max

    def feasible(self, fitness: FloatArray | float) -> BoolArray:
        """Whether fitness values belong to feasible candidates (the one rule: at most ``t_max``)."""
        return np.asarray(np.asarray(fitness) <= self.t_max)

    @property
    def dimension(self) -> int:
        """Length of a decision vector: waypoints x moving joints."""
        return int(self.lower.size)

    def nodes(self, x: FloatArray) -> FloatArray:
        """``(S, p + 2, nq)`` start, waypoints and goal of candidates ``x`` ``(S, p k)``."""
        return self.motion.nodes(x, self.n_waypoints)

    def straight_line(self) -> FloatArray:
        """The decision vector whose waypoints lie evenly on the straight line from start to goal."""
        return self.motion.straight_line(self.n_waypoints)

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

    def checked_configurations(self, samples: FloatArray) -> FloatArray:
        """The configurations the fitness checks for a path's ``samples`` ``(..., nq)``: within the ranges."""
        return np.clip(samples, self.lower_q, self.upper_q)

    def __call__(self, x: FloatArray) -> FloatArray:
        """``(S,)`` fitness of candidates ``x`` ``(S, p k)`` in joint units."""
        return self.breakdown(x).fitness

    def _clearance(self, samples: FloatArray, may_be_feasible: BoolArray) -> FloatArray:
        """``(S, K, 2)`` per-group clearance where it falls short of the required clearance.

        ``inf`` where a sample keeps the required clearance, ``nan`` where it was not checked.
        Staged: every :data:`FIRST_PASS_STRIDE`-th sample first, for every candidate; the
        others only for candidates clear there that ``may_be_feasible`` (no other violation),
        the only ones whose feasibility the remaining samples decide. An infeasible candidate
        so costs a fraction, its depth the mean over the coarse samples. Where coal's parallel
        yes/no test flags a sample, its distance is computed.
        """
        s, k, _ = samples.shape
        clearance = np.full((s, k, 2), np.nan)
        coarse = np.zeros(k, dtype=bool)
        coarse[::FIRST_PASS_STRIDE] = True
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
            values[flagged] = self.rule.shortfall_distances(
                self.world, flat[flagged], self.required_m, self._pair_group
            )
        if self.world.self_collision:  # a violation of the self margin counts as the links' own
            hit = np.flatnonzero(self.world.self_collision.violated(flat, self.required_self_m))
            if hit.size:
                distance, _ = self.world.self_collision.distances(flat[hit])
                shifted = distance - self.required_self_m + self.required_m  # below required_m as deep
                values[hit, LINKS] = np.minimum(values[hit, LINKS], shifted)
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
        configurations = self.checked_configurations(paths.samples)
        holding = np.zeros(len(x)) if self.gravity is None else self.gravity.path_excess(configurations)
        other = paths.overshoot + excess + deviation_excess + holding
        clearance = self._clearance(configurations, other <= 0.0)
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
        fitness = self.rule.fitness(Terms(base, feasible, links, depth, other, self.t_max, self.required_m))
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
            holding_excess=holding,
            min_clearance_m=np.nanmin(clearance, axis=(1, 2)),
        )
