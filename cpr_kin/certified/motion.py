"""Continuous clearance checks of joint-space curves, with a kinematic motion bound.

If joint ``j`` moves by ``dq_j``, no point of the robot moves more than
``sum_j R_j |dq_j|``, where ``R_j`` is 1 for a prismatic joint and, for a revolute joint,
a bound on the distance of any point it carries from its axis (the *motion radius*,
see :func:`motion_radii`), valid in every configuration.

A curve ``q(t)`` whose joint speeds are bounded by ``v_j`` therefore moves every robot point
at most ``V = sum_j R_j v_j`` [m/s]. Sampling it every ``dt = 2 step_m / V`` leaves no
instant farther than ``step_m`` of robot motion from a sample. Since every distance changes
at most as fast as the robot moves, between samples ``k`` and ``k+1`` the clearance is at
least ``(c_k + c_{k+1} - V dt) / 2 >= min(c_k, c_{k+1}) - step_m``: that certified lower
bound, not the sampled value, is compared with the margin. A grid of thousands of samples is
sampled every few samples first, finely only where its minima may lie
(:mod:`cpr_kin.certified.coarse_first`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.certified.coarse_first import GridSampler, IntervalSpeed, coarse_first, fine_slack
from cpr_kin.collision.clearance import BatchClearance
from cpr_kin.collision.decisive import (
    Stop,
    certified,
    chunked,
    exact_below,
    first_rows,
    undecided,
    with_neighbours,
)
from cpr_kin.collision.robot_reach import robot_reach
from cpr_kin.collision.world import CollisionWorld
from cpr_kin.common.errors import CprKinError
from cpr_kin.model.robot import GROUPS, Robot

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

LOWER_BOUND_ROWS = 4096
"""Configurations bounded in one call (a few tenths of a second on meshes): one piece's pair
bounds, ``(rows, P)``, are reduced to their groups' minima before the next is computed."""
MAX_CURVE_CHECKS = 1_000_000
"""Most configurations one continuous check queries (about 10 to 20 s of coal on 2 cores)."""


def motion_radii(robot: Robot) -> FloatArray:
    """Per-joint motion radius ``R_j``: [m/rad] for revolute, 1 [m/m] for prismatic joints.

    A displacement ``dq`` of the joints moves no point of any collision geometry by more
    than ``sum_j R_j |dq_j|`` [m], whatever the configuration (see :mod:`cpr_kin.bounds.reach`).
    """
    return np.asarray(np.max([r.radii for r in robot_reach(robot)], axis=0))


PATH_WEIGHT_FLOOR = 0.01
"""A path metric's weight of a joint that moves no collision geometry, as a share of the largest."""


def path_weights(robot: Robot) -> FloatArray:
    """Per-joint weights of a joint-space path's length: the motion radii, none zero [m/rad, m/m].

    A joint that carries no collision geometry (a gripper, or a wrist roll whose link has
    only a visual mesh, as the SO-100's) has motion radius 0: moving it moves nothing that
    can collide. A path must still move it to its goal, and a sampling planner's distances,
    steps and shortcuts must see it: its weight is :data:`PATH_WEIGHT_FLOOR` of the largest
    radius. The other joints keep their radii.
    """
    radii = motion_radii(robot)
    return np.where(radii > 0.0, radii, PATH_WEIGHT_FLOOR * float(radii.max(initial=0.0)) or 1.0)


@dataclass(frozen=True)
class CurveCheck:
    """Result of a continuous clearance check.

    Attributes:
        accepted: the certified clearance is at least the margin everywhere.
        margin_m: the required clearance [m].
        step_m: the stated bound on robot motion between two checks [m].
        times: ``(K,)`` sampled instants [s].
        clearance_m: ``(K, 2)`` sampled clearance per group [m] (columns as :data:`GROUPS`):
            exact (coal) where it decides a minimum, a lower bound elsewhere
            (see :func:`decisive_clearance`).
        certified_min_m: lower bound of the clearance over the whole curve [m].
        sampled_min_m: smallest sampled clearance [m].
        worst_time: instant of the smallest sampled clearance [s].
        worst_group: group of the smallest sampled clearance.
        worst_pair: ``(robot geometry, obstacle)`` closest at :attr:`worst_time`.
        violating_groups: groups whose certified clearance falls below the margin.

    """

    accepted: bool
    margin_m: float
    step_m: float
    times: FloatArray
    clearance_m: FloatArray
    certified_min_m: float
    sampled_min_m: float
    worst_time: float
    worst_group: str
    worst_pair: tuple[str, str] | None
    violating_groups: tuple[str, ...]


def check_curve(
    world: CollisionWorld,
    curve: Callable[[FloatArray], FloatArray],
    t0: float,
    t1: float,
    speed_bound: ArrayLike,
    margin_m: float,
    step_m: float = 0.005,
    interval_speed: IntervalSpeed | None = None,
    *,
    stop: Stop | None = None,
) -> CurveCheck:
    """Certify that the curve ``q(t)``, ``t0 <= t <= t1``, keeps ``margin_m`` everywhere.

    Args:
        world: robot and obstacles.
        curve: vectorised ``q(t)``: times ``(K,)`` [s] -> configurations ``(K, nq)``.
        t0: start time [s].
        t1: end time [s].
        speed_bound: ``(nq,)`` bounds on ``|dq_j/dt|`` over the interval [rad/s, m/s].
        margin_m: required clearance [m].
        step_m: largest robot motion between two checks [m].
        interval_speed: bounds on the robot's point speed over each interval between the
            sample times (:data:`cpr_kin.certified.coarse_first.IntervalSpeed`); each interval's
            certified bound uses the lower of it and ``speed_bound``'s. The samples are
            those of ``speed_bound``.
        stop: asked between the check's pieces of work (:data:`cpr_kin.collision.decisive.Stop`).

    Raises:
        CprKinError: bad arguments, or more than :data:`MAX_CURVE_CHECKS` samples needed.
        CheckStoppedError: ``stop`` said so before the verdict.

    """
    speed = np.asarray(speed_bound, dtype=float)
    if speed.shape != (world.robot.nq,) or not np.all(np.isfinite(speed)) or np.any(speed < 0):
        raise CprKinError(f"speed bound {speed.tolist()} must be {world.robot.nq} finite numbers >= 0")
    if not (np.isfinite(step_m) and step_m > 0):
        raise CprKinError(f"motion step {step_m} m must be a finite number > 0")
    if not (np.isfinite(t0) and np.isfinite(t1) and t1 >= t0):
        raise CprKinError(f"time interval [{t0}, {t1}] s must be finite with t1 >= t0")
    point_speed = float(motion_radii(world.robot) @ speed)
    duration = t1 - t0
    count = int(np.ceil(duration * point_speed / (2.0 * step_m))) + 1 if point_speed > 0 else 1
    if count > MAX_CURVE_CHECKS:
        raise CprKinError(
            f"the continuous check needs {count} samples ({duration:.4g} s of motion at up to "
            f"{point_speed:.3g} m/s, step {step_m:g} m); at most {MAX_CURVE_CHECKS}: use a larger step"
        )
    times = np.linspace(t0, t1, max(count, 2))  # at least both ends

    slack, largest_slack_m = fine_slack(times, point_speed, interval_speed)
    exact_m = exact_below(margin_m, largest_slack_m)

    def decide(rows: IntArray, rows_slack: FloatArray) -> tuple[FloatArray, IntArray]:
        batch = decisive_clearance(world, curve(times[rows]), rows_slack, exact_m, stop=stop)
        return batch.clearance_m, batch.closest_pair

    def exact(rows: IntArray) -> tuple[FloatArray, IntArray]:
        q, every = curve(times[rows]), np.arange(len(rows))
        groups = [
            chunked(partial(_group_clearance, world, q, g, exact_m), every, stop) for g in range(len(GROUPS))
        ]
        return np.stack([g[0] for g in groups], axis=1), np.stack([g[1] for g in groups], axis=1)

    grid = coarse_first(GridSampler(len(times), decide, exact, slack, largest_slack_m))
    per_group, closest_pair = grid.values, grid.closest
    # lower bound between neighbouring samples: distances change no faster than the robot moves
    group_bound = certified(per_group, grid.slack).min(axis=0)
    sample_min = per_group.min(axis=1)
    worst = int(np.argmin(sample_min))
    worst_group_index = int(np.argmin(per_group[worst]))
    pair_index = int(closest_pair[worst, worst_group_index])
    worst_pair = world.pairs[pair_index][:2] if pair_index >= 0 else None
    certified_min = float(group_bound.min())
    return CurveCheck(
        accepted=bool(certified_min >= margin_m),
        margin_m=float(margin_m),
        step_m=float(step_m),
        times=times,
        clearance_m=per_group,
        certified_min_m=certified_min,
        sampled_min_m=float(sample_min[worst]),
        worst_time=float(times[worst]),
        worst_group=GROUPS[worst_group_index],
        worst_pair=worst_pair,
        violating_groups=tuple(g for g, b in zip(GROUPS, group_bound, strict=True) if b < margin_m),
    )


def decisive_clearance(
    world: CollisionWorld,
    q: FloatArray,
    slack_m: float | FloatArray,
    exact_below_m: float = np.inf,
    *,
    stop: Stop | None = None,
) -> BatchClearance:
    """Per-group clearance of the samples ``q`` ``(K, nq)`` of a curve, exact where it decides the check.

    :func:`check_curve` needs, per group, the smallest certified value
    ``(c_k + c_{k+1} - slack_m) / 2`` and the smallest sampled clearance, each exactly (coal).
    ``slack_m`` (one value, or one per interval ``(K - 1,)``) bounds how far any robot point
    moves between neighbouring samples [m], so a clearance changes by at most that much.
    Every sample starts with its cheap lower bound
    (:meth:`~cpr_kin.CollisionWorld.clearance_lower_bounds`); coal then computes, in rounds,
    the samples that could still be below the smallest exact value (a share of them first
    where many are in doubt, :func:`~cpr_kin.collision.decisive.first_rows`), and each exact
    value bounds its neighbours (its value less the motion between them, less coal's own
    tolerance), until the minima are exact. Values computed from lower bounds are
    at most the true ones, so a minimum found exactly is the true minimum. Elsewhere
    :attr:`clearance_m` holds the best lower bound and :attr:`closest_pair` ``-1``. A value at
    or above ``exact_below_m`` [m] need not be exact (a link's exact mesh that far from an
    obstacle counts as that far, :meth:`~cpr_kin.CollisionWorld.group_clearance`): a check whose
    margin plus slack is below it decides the same. ``stop`` is asked between pieces of
    :data:`~cpr_kin.collision.decisive.CHUNK_ROWS` configurations (:class:`~cpr_kin.CheckStoppedError`).
    """
    bounds = group_lower_bounds(world, q, stop)
    values = bounds.copy()
    known = np.isinf(values) & (values > 0)  # groups without pairs: nothing to compute
    closest = np.full(values.shape, -1, dtype=np.int64)
    slack = np.broadcast_to(np.asarray(slack_m, dtype=float), (max(len(q) - 1, 0),))
    reach = np.concatenate([[0.0], np.cumsum(slack)])
    while (needed := undecided(values, known, slack_m)).any():
        for group_index in range(values.shape[1]):
            rows = first_rows(np.flatnonzero(needed[:, group_index]))
            if rows.size:
                exact = partial(_group_clearance, world, q, group_index, exact_below_m)
                values[rows, group_index], closest[rows, group_index] = chunked(exact, rows, stop)
                known[rows, group_index] = True
                values[:, group_index] = with_neighbours(
                    values[:, group_index], known[:, group_index], bounds[:, group_index], reach
                )
    return BatchClearance(clearance_m=values, closest_pair=closest)


def group_lower_bounds(world: CollisionWorld, q: FloatArray, stop: Stop | None = None) -> FloatArray:
    """``(K, len(GROUPS))`` :meth:`~cpr_kin.CollisionWorld.clearance_lower_bounds` at ``q`` ``(K, nq)``.

    :data:`LOWER_BOUND_ROWS` configurations at a time, ``stop`` asked before each piece. Every
    pair's bounds at every sample, kept whole, held hundreds of megabytes for a long check among
    many obstacles (a Fetch's among MotionBenchMaker's shelves: 225 pairs at up to 400,000
    samples, the finer step of ends a fraction of a millimetre from a shelf), and a process
    peaked at 1.6 GB; the rows coal decides get theirs again (:func:`_group_clearance`).
    """
    pieces = [
        chunked(world.clearance_lower_bounds, q[first : first + LOWER_BOUND_ROWS], stop, LOWER_BOUND_ROWS)
        for first in range(0, len(q), LOWER_BOUND_ROWS)
    ]
    return np.concatenate(pieces) if pieces else np.empty((0, len(GROUPS)))


def _group_clearance(
    world: CollisionWorld, q: FloatArray, group: int, exact_below_m: float, rows: IntArray
) -> tuple[FloatArray, IntArray]:
    """:meth:`~cpr_kin.CollisionWorld.group_clearance` at samples ``rows`` of ``q``, bounded anew."""
    return world.group_clearance(q[rows], group, exact_below_m)


def check_segment(
    world: CollisionWorld, q_start: ArrayLike, q_goal: ArrayLike, margin_m: float, step_m: float = 0.005
) -> CurveCheck:
    """Continuous check of the straight joint-space segment from ``q_start`` to ``q_goal``.

    The segment is parametrised by ``s`` in [0, 1] (reported as :attr:`CurveCheck.times`).
    """
    start = world.robot.configuration(q_start)
    goal = world.robot.configuration(q_goal)
    delta = goal - start

    def line(s: FloatArray) -> FloatArray:
        return np.asarray(start + np.outer(s, delta))

    return check_curve(world, line, 0.0, 1.0, np.abs(delta), margin_m, step_m)
