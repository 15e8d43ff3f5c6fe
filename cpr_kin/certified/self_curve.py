"""The certified self-collision check of a curve, pair by pair, each at its own relative speed.

The joints that carry both geometries of a pair move them together and leave their distance
as it is; only a joint that carries one and not the other changes it, at most as fast as
that geometry's points turn about the joint's axis (its *motion radius* about the joint,
:class:`cpr_kin.bounds.reach.GeometryReach`). So pair ``p``'s distance changes at most as fast as
``sum_j R_pj |q'_j|`` (:func:`cpr_kin.bounds.reach.relative_radii`): a forearm and the wrist two
joints down the
chain, always a centimetre apart, move against each other many times slower than the hand
moves in the world. Each pair is sampled at its own rate, every ``2 step_m`` of its relative
motion, and between its samples ``k`` and ``k + 1`` its distance is at least
``(c_k + c_{k+1} - slack_k) / 2``, at most ``step_m`` below the smaller sample, as in the
obstacle check (:func:`cpr_kin.check_curve`).

The pairs are first screened by their capsules
(:meth:`cpr_kin.collision.self_collision.SelfCollision.bounds`) on one coarser grid, and visited from
the lowest bound the screen gives; a pair that cannot lower the minima found so far is
skipped, and within a pair coal computes only the samples that decide
(:func:`cpr_kin.collision.decisive.undecided`), a long grid every few samples first
(:func:`cpr_kin.certified.coarse_first.coarse_first`). The minima reported are those of
computing every sample of every pair.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.certified.coarse_first import GridSampler, coarse_first, fine_slack
from cpr_kin.certified.pair_samples import JointSpeeds, PairSampler, relative_speed
from cpr_kin.collision.decisive import Stop, ask, below_coal, certified, exact_below
from cpr_kin.common.errors import CprKinError

if TYPE_CHECKING:
    from cpr_kin.collision.self_collision import SelfCollision

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

MAX_SELF_CHECKS = 1_000_000
"""Most samples the certified self-collision check of a curve takes of one pair."""
SCREEN_STRIDE = 8
"""The screen's grid is this many times coarser than the fastest pair's samples."""


@dataclass(frozen=True)
class SelfCheck:
    """Result of :func:`check_self_curve`.

    Attributes:
        accepted: the certified self-clearance is at least the margin everywhere.
        margin_m: the self-clearance required [m].
        checks: samples taken, summed over the pairs (each pair at its own rate).
        computed: those whose distance coal computed, the others bounded.
        certified_min_m: lower bound of the self-clearance over the whole curve [m]
            (``inf`` without pairs).
        worst_time: instant of the smallest sampled self-clearance [s].
        worst_pair: the geometry pair closest then, or ``None``.
    """

    accepted: bool
    margin_m: float
    checks: int
    computed: int
    certified_min_m: float
    worst_time: float
    worst_pair: tuple[str, str] | None


def check_self_curve(
    collision: SelfCollision,
    curve: Callable[[FloatArray], FloatArray],
    interval: tuple[float, float],
    joint_speed: ArrayLike,
    margin_m: float,
    step_m: float,
    interval_joint_speed: JointSpeeds | None = None,
    *,
    stop: Stop | None = None,
) -> SelfCheck:
    """Certify that the curve ``q(t)`` over ``interval`` keeps ``margin_m`` between the robot's own pairs.

    Args:
        collision: the robot's pairs.
        curve: vectorised ``q(t)``: times ``(K,)`` [s] -> configurations ``(K, nq)``.
        interval: ``(t0, t1)`` [s].
        joint_speed: ``(nj,)`` bounds on ``|q'_j|`` over the interval [rad/s, m/s].
        margin_m: the self-clearance required [m].
        step_m: largest relative motion of a pair between two of its samples [m].
        interval_joint_speed: tighter bounds per interval between samples
            (:data:`JointSpeeds`); each interval's slack uses the lower of both.
        stop: asked between the check's pieces of work (:data:`cpr_kin.collision.decisive.Stop`).

    Raises:
        CprKinError: bad arguments, or a pair needing more than :data:`MAX_SELF_CHECKS` samples.
        CheckStoppedError: ``stop`` said so before the verdict.
    """
    t0, t1 = interval
    if not collision:
        return SelfCheck(True, float(margin_m), 0, 0, np.inf, t0, None)
    speed = np.asarray(joint_speed, dtype=float)
    radii = collision.pair_radii
    if speed.shape != radii.shape[1:] or not np.all(np.isfinite(speed) & (speed >= 0)):
        raise CprKinError(f"joint speed bound {speed.tolist()} must be {radii.shape[1]} finite numbers >= 0")
    if not (np.isfinite(step_m) and step_m > 0):
        raise CprKinError(f"motion step {step_m} m must be a finite number > 0")
    pair_speed = radii @ speed  # [m/s]
    counts = np.maximum(np.ceil((t1 - t0) * pair_speed / (2.0 * step_m)).astype(np.int64) + 1, 2)
    if counts.max() > MAX_SELF_CHECKS:
        p = int(np.argmax(counts))
        raise CprKinError(
            f"the self-collision check of {collision.pairs[p]} needs {counts[p]} samples ({t1 - t0:.4g} s "
            f"of motion at up to {pair_speed[p]:.3g} m/s, step {step_m:g} m); at most {MAX_SELF_CHECKS}: "
            "use a larger step"
        )

    ask(stop)
    screen = _screen(collision, curve, (t0, t1), pair_speed, step_m, interval_joint_speed)
    certified_min, sampled_min, worst_time, worst_pair, computed = np.inf, np.inf, t0, -1, 0
    for p in np.argsort(screen, kind="stable"):
        # the screen bounds the pair's distance everywhere, its samples' certified value to step_m less
        if screen[p] - step_m >= certified_min and screen[p] >= sampled_min:
            continue  # neither minimum can come from this pair
        ask(stop)
        times = np.linspace(t0, t1, int(counts[p]))
        slack, largest_m = fine_slack(
            times, pair_speed[p], relative_speed(collision, int(p), interval_joint_speed)
        )
        ceilings = (certified_min, sampled_min)
        pair = PairSampler(collision, int(p), curve, times, exact_below(margin_m, largest_m), ceilings, stop)
        grid = coarse_first(GridSampler(len(times), pair.decide, pair.exact, slack, largest_m), ceilings)
        values, known = grid.values[:, 0], grid.closest[:, 0] >= 0
        computed += pair.computed
        certified_min = min(certified_min, float(np.min(certified(values, grid.slack))))
        lowest = int(np.argmin(values))
        if known[lowest] and values[lowest] < sampled_min:
            sampled_min, worst_time, worst_pair = float(values[lowest]), float(times[lowest]), int(p)
    return SelfCheck(
        accepted=bool(certified_min >= margin_m),
        margin_m=float(margin_m),
        checks=int(counts.sum()),
        computed=computed,
        certified_min_m=certified_min,
        worst_time=worst_time,
        worst_pair=collision.pairs[worst_pair] if worst_pair >= 0 else None,
    )


def _screen(
    collision: SelfCollision,
    curve: Callable[[FloatArray], FloatArray],
    interval: tuple[float, float],
    pair_speed: FloatArray,
    step_m: float,
    interval_joint_speed: JointSpeeds | None,
) -> FloatArray:
    """``(P,)`` lower bounds [m] of each pair's distance over the whole curve, from its capsules.

    One grid for every pair, every ``2 SCREEN_STRIDE step_m`` of the fastest pair's relative
    motion; each pair's bound is its smallest ``(b_k + b_{k+1} - slack_k) / 2``.
    """
    t0, t1 = interval
    count = max(int(np.ceil((t1 - t0) * pair_speed.max() / (2.0 * SCREEN_STRIDE * step_m))) + 1, 2)
    times = np.linspace(t0, t1, count)
    speed = np.broadcast_to(pair_speed, (count - 1, len(pair_speed)))
    if interval_joint_speed is not None:
        speed = np.minimum(speed, interval_joint_speed(times) @ collision.pair_radii.T)
    bounds = below_coal(collision.bounds(curve(times)))
    return np.asarray(np.min(certified(bounds, speed * np.diff(times)[:, None]), axis=0))
