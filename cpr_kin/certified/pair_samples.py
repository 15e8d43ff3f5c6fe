"""One pair's samples of a curve for the certified self check: its capsules bound them, coal decides.

:func:`~cpr_kin.certified.self_curve.check_self_curve` samples each pair at its own rate, on a
grid that :func:`~cpr_kin.certified.coarse_first.coarse_first` may sample coarsely first;
:class:`PairSampler` gives it the pair's values where it asks: the capsules' lower bound at
every sample, and coal's distance at those that could still lower the check's minima
(:func:`~cpr_kin.collision.decisive.undecided`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from cpr_kin.certified.coarse_first import IntervalSpeed
from cpr_kin.collision.decisive import (
    Stop,
    below_coal,
    certified,
    chunked,
    first_rows,
    undecided,
    with_neighbours,
)

if TYPE_CHECKING:
    from cpr_kin.collision.self_collision import SelfCollision

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

JointSpeeds = Callable[[FloatArray], FloatArray]
"""Sample times ``(K,)`` [s] -> ``(K - 1, nj)`` bounds on ``|q'_j|`` over each interval between
them [rad/s, m/s] (e.g. :meth:`~planning.curves.trajectory.Trajectory.speed_bounds`)."""


@dataclass(frozen=True)
class _PairSamples:
    """One pair's samples: index, times ``(K,)`` [s], configurations, slack per interval [m], bounds [m]."""

    index: int
    times: FloatArray
    q: FloatArray
    slack: FloatArray
    bounds: FloatArray

    @property
    def certified_bound(self) -> float:
        """The lowest certified value the capsule bounds allow [m]."""
        return float(np.min(certified(self.bounds, self.slack)))


def relative_speed(
    collision: SelfCollision, index: int, interval_joint_speed: JointSpeeds | None
) -> IntervalSpeed | None:
    """Bounds on how fast pair ``index``'s geometries move apart over each interval between sample times."""
    if interval_joint_speed is None:
        return None
    radii = collision.pair_radii[index]
    return lambda times: interval_joint_speed(times) @ radii


class PairSampler:
    """One pair's samples of a curve at ``times``, where the fine grid asks for them.

    The capsules bound every sample, coal computes those that decide (:func:`_decisive_values`)
    below the ``ceilings``, the check's minima over the pairs before it [m]; a value at or above
    ``exact_below_m`` [m] need not be exact. ``computed`` counts coal's samples; ``stop`` is asked
    before each call to coal.
    """

    def __init__(
        self,
        collision: SelfCollision,
        index: int,
        curve: Callable[[FloatArray], FloatArray],
        times: FloatArray,
        exact_below_m: float,
        ceilings: tuple[float, float],
        stop: Stop | None,
    ) -> None:
        self.collision, self.index, self.curve, self.times = collision, index, curve, times
        self.exact_below_m, self.ceilings, self.stop = exact_below_m, ceilings, stop
        self.computed = 0

    def decide(self, rows: IntArray, slack: FloatArray) -> tuple[FloatArray, IntArray]:
        """The pair's values at ``rows`` as one curve, exact where they decide; the pair where exact."""
        q = np.asarray(self.curve(self.times[rows]), dtype=float)
        bounds = below_coal(self.collision.pair_bounds(q, self.index))  # at most coal's distance
        pair = _PairSamples(self.index, self.times[rows], q, slack, bounds)
        certified_ceiling, sampled_ceiling = self.ceilings
        if pair.certified_bound >= certified_ceiling and bounds.min() >= sampled_ceiling:
            values, known = bounds, np.zeros(len(rows), dtype=bool)  # cannot lower a minimum
        else:
            values, known = _decisive_values(
                self.collision, pair, self.ceilings, self.exact_below_m, self.stop
            )
        self.computed += int(known.sum())
        return values[:, None], np.where(known, self.index, -1)[:, None]

    def exact(self, rows: IntArray) -> tuple[FloatArray, IntArray]:
        """The pair's distance at ``rows``, by coal."""
        q = np.asarray(self.curve(self.times[rows]), dtype=float)
        distance = partial(self.collision.pair_distances, pair=self.index, exact_below_m=self.exact_below_m)
        self.computed += len(rows)
        return chunked(distance, q, self.stop)[:, None], np.full((len(rows), 1), self.index)


def _decisive_values(
    collision: SelfCollision,
    pair: _PairSamples,
    ceilings: tuple[float, float],
    exact_below_m: float,
    stop: Stop | None,
) -> tuple[FloatArray, NDArray[np.bool_]]:
    """The pair's distances [m] at its samples, exact where they decide, else lower bounds; which are exact.

    Decide: could lower the pair's smallest certified or sampled value below the ``ceilings``
    (the check's minima so far, certified and sampled) [m]. The capsules' bounds and the
    exact values' neighbours (distances change by at most the slack per interval) bound the
    others. A value counts as exact where the hulls' distance is at or above ``exact_below_m``
    [m]: the meshes' distance is no smaller, and the check cannot fail there. ``stop`` is
    asked before each call to coal.
    """
    certified_ceiling, sampled_ceiling = ceilings
    count = len(pair.times)
    values, known = pair.bounds.copy(), np.zeros(count, dtype=bool)
    reach = np.concatenate([[0.0], np.cumsum(pair.slack)])
    doubtful = np.zeros(count, dtype=bool)
    low = certified(values, pair.slack) < certified_ceiling
    doubtful[:-1] |= low
    doubtful[1:] |= low
    rows = first_rows(np.flatnonzero(doubtful), coarse_from=1)  # then all that are left
    while rows.size:
        exact = partial(collision.pair_distances, pair=pair.index, exact_below_m=exact_below_m)
        values[rows] = chunked(exact, pair.q[rows], stop)
        known[rows] = True
        values = with_neighbours(values, known, pair.bounds, reach)
        needed = undecided(values[:, None], known[:, None], pair.slack, certified_ceiling, sampled_ceiling)
        rows = np.flatnonzero(needed[:, 0])
    return values, known
