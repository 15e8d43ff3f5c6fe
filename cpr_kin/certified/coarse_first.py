"""A certified check's fine grid computed only where it can decide: every few samples first, then the rest.

A certified check samples a curve on a grid fine enough that the robot moves at most its step
between neighbours, and reports per group (a column) the smallest certified value
``(c_k + c_{k+1} - slack_k) / 2`` and the smallest sampled value. An end a fraction of a
millimetre beyond its margin (a grasp on a shelf) asks for a step as fine, and a grid of
hundreds of thousands of samples, though only those about the closest approach decide
anything. :func:`coarse_first` takes every :data:`STRIDE`-th sample first. Their values and
the robot's motion between them bound the clearance over each coarse interval
(:func:`~cpr_kin.collision.decisive.certified`): a fine sample there is at least that bound,
and a fine interval's certified value at least that bound less half its own slack. Where that
could still be below the minima, the interval's ends are computed exactly, and where it still
could, the interval is sampled finely; until no interval is left that could. The minima are
the whole fine grid's; elsewhere the grid holds the coarse bound.

The slack between samples is how far a robot point may move between them
(:func:`interval_motion`). One speed bound for the whole curve is its peak, reached
mid-motion; near the ends, where a trajectory starts and stops at rest and often passes
closest to an obstacle (a grasp, a placement), the robot moves far slower, and an interval's
own speed bound (:data:`IntervalSpeed`) certifies what the peak cannot.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cpr_kin.collision.decisive import certified
from cpr_kin.common.arrays import distinct_sorted

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]
BoolArray = NDArray[np.bool_]

STRIDE = 8
"""Every how many samples of the fine grid the coarse one takes."""
FROM_SAMPLES = 4096
"""Fine grids of fewer samples are computed whole (the coarse pass would save less than it costs)."""

Values = Callable[[IntArray, FloatArray], tuple[FloatArray, IntArray]]
"""Sample indices ``(n,)`` of the fine grid, increasing, and the motion between them ``(n - 1,)``
[m] -> values ``(n, G)`` [m] and closest pairs ``(n, G)``: exact where the pair is ``>= 0``,
lower bounds elsewhere (pair ``-1``)."""
Exact = Callable[[IntArray], tuple[FloatArray, IntArray]]
"""Sample indices ``(n,)`` -> values and closest pairs ``(n, G)``, exact in every column with pairs."""
Slack = Callable[[IntArray], FloatArray]
"""Sample indices ``(n,)``, increasing -> ``(n - 1,)`` bounds on the motion between neighbours [m]."""
IntervalSpeed = Callable[[FloatArray], FloatArray]
"""Sample times ``(K,)`` [s] -> ``(K - 1,)`` bounds on the robot's point speed over each
interval between them [m/s] (e.g. ``motion_radii @`` a trajectory's
:meth:`~planning.curves.trajectory.Trajectory.speed_bounds`)."""


@dataclass(frozen=True)
class GridSampler:
    """How a certified check samples its curve on a fine grid.

    Attributes:
        count: samples of the fine grid.
        decide: values at samples taken as one curve, exact where they decide its minima
            (:func:`~cpr_kin.certified.motion.decisive_clearance`).
        exact: values at samples, exact in every column that has pairs.
        slack: the motion between samples.
        largest_slack_m: a bound on the motion between any two neighbours of the fine grid [m].
    """

    count: int
    decide: Values
    exact: Exact
    slack: Slack
    largest_slack_m: float


@dataclass(frozen=True)
class FineGrid:
    """A certified check's samples: values and closest pairs ``(K, G)``, slack ``(K - 1,)`` [m].

    Exact where they decide a minimum; elsewhere lower bounds (pair ``-1``). An interval not
    sampled finely has as its slack a bound on it, from its coarse interval's.
    """

    values: FloatArray
    closest: IntArray
    slack: FloatArray


def interval_motion(
    times: FloatArray, point_speed: float, interval_speed: IntervalSpeed | None
) -> FloatArray:
    """``(K - 1,)`` how far any robot point may move between neighbouring ``times`` [m].

    ``point_speed`` bounds the speed on the whole curve [m/s]; ``interval_speed``, when
    given, per interval; the lower of the two counts.
    """
    speed = np.full(len(times) - 1, float(point_speed))
    if interval_speed is not None and len(times) > 1:
        speed = np.minimum(speed, interval_speed(times))
    return np.asarray(speed * np.diff(times))


def fine_slack(times: FloatArray, speed: float, interval_speed: IntervalSpeed | None) -> tuple[Slack, float]:
    """The slack of the grid ``times`` [s] (:func:`interval_motion`) and a bound on its largest [m].

    ``speed`` bounds the motion's speed over the whole curve [m/s], ``interval_speed`` over each
    interval. Where :func:`coarse_first` samples the grid whole, its slack is computed once and
    its own largest given; else ``speed`` times the largest interval's duration.
    """

    def slack(rows: IntArray) -> FloatArray:
        return interval_motion(times[rows], speed, interval_speed)

    count = len(times)
    if count >= FROM_SAMPLES:
        return slack, speed * float(np.max(np.diff(times)))
    whole = slack(np.arange(count))
    return (lambda rows: whole if len(rows) == count else slack(rows)), float(np.max(whole, initial=0.0))


def coarse_first(sampler: GridSampler, ceilings: tuple[float, float] = (np.inf, np.inf)) -> FineGrid:
    """The fine grid of ``sampler``, its minima exact, sampled finely only where they may lie.

    ``ceilings``: a certified and a sampled value found elsewhere [m] (another pair's); a
    minimum at or above them need not be exact, and an interval that cannot go below them
    is not sampled finely.
    """
    count = sampler.count
    if count < FROM_SAMPLES:
        every = np.arange(count)
        slack = sampler.slack(every)
        return FineGrid(*sampler.decide(every, slack), slack)
    coarse = distinct_sorted(np.arange(0, count, STRIDE), count - 1)
    slack = sampler.slack(coarse)
    fine_bound = np.minimum(slack, sampler.largest_slack_m)  # on a fine interval's slack in each
    values, closest = sampler.decide(coarse, slack)
    known = (closest >= 0) | np.isposinf(values)
    # each sampled value bounds the minima of the fine grid, which holds the sample, from above
    sampled_min = np.minimum(np.min(np.where(known, values, np.inf), axis=0), ceilings[1])
    certified_min = np.minimum(sampled_min, ceilings[0])
    fine = _Fine(count)
    done = np.zeros(len(coarse) - 1, dtype=bool)
    while True:
        floor = certified(values, slack)  # the clearance anywhere in each coarse interval
        wanted = ~done & np.any(
            (floor - 0.5 * fine_bound[:, None] < certified_min) | (floor <= sampled_min), axis=1
        )
        ends = distinct_sorted(np.flatnonzero(wanted), np.flatnonzero(wanted) + 1)
        doubtful = ends[~known[ends].all(axis=1)]
        if doubtful.size:  # exact ends may lift an interval's floor above the minima
            values[doubtful], closest[doubtful] = sampler.exact(coarse[doubtful])
            known[doubtful] = True
            sampled_min = np.minimum(sampled_min, values[doubtful].min(axis=0))
            certified_min = np.minimum(certified_min, sampled_min)
            continue
        if not wanted.any():
            return fine.grid(coarse, values, closest, floor, fine_bound)
        for first, last in _runs(wanted):
            rows = np.arange(coarse[first], coarse[last + 1] + 1)
            run_values, run_slack = fine.sample(rows, sampler)
            certified_min = np.minimum(certified_min, certified(run_values, run_slack).min(axis=0))
            sampled_min = np.minimum(sampled_min, run_values.min(axis=0))
        done |= wanted


class _Fine:
    """The runs of the fine grid sampled so far."""

    def __init__(self, count: int) -> None:
        self.count = count
        self.runs: list[tuple[IntArray, FloatArray, IntArray, FloatArray]] = []

    def sample(self, rows: IntArray, sampler: GridSampler) -> tuple[FloatArray, FloatArray]:
        """The values and slack of the consecutive fine ``rows``, sampled as one curve (kept, with pairs)."""
        slack = sampler.slack(rows)
        values, closest = sampler.decide(rows, slack)
        self.runs.append((rows, values, closest, slack))
        return values, slack

    def grid(
        self,
        coarse: IntArray,
        values: FloatArray,
        closest: IntArray,
        floor: FloatArray,
        fine_bound: FloatArray,
    ) -> FineGrid:
        """The whole grid: the runs, the coarse samples, elsewhere each coarse interval's ``floor``.

        An interval not sampled finely has as its slack ``fine_bound``, its coarse interval's
        bound on a fine one's.
        """
        interval = np.minimum(
            np.searchsorted(coarse, np.arange(self.count), side="right") - 1, len(coarse) - 2
        )
        grid = FineGrid(
            floor[interval],
            np.full((self.count, values.shape[1]), -1, dtype=np.int64),
            fine_bound[interval[:-1]],
        )
        for rows, run_values, run_closest, run_slack in self.runs:
            grid.values[rows], grid.closest[rows], grid.slack[rows[:-1]] = run_values, run_closest, run_slack
        # a coarse sample exact at either level keeps its exact value; a bound, the best of its bounds
        sampled, paired = grid.values[coarse], grid.closest[coarse]
        floors = np.maximum(np.r_[floor[:1], floor], np.r_[floor, floor[-1:]])
        best_bound = np.maximum(np.maximum(sampled, values), floors)
        grid.values[coarse] = np.where(closest >= 0, values, np.where(paired >= 0, sampled, best_bound))
        grid.closest[coarse] = np.where(closest >= 0, closest, paired)
        return grid


def _runs(wanted: BoolArray) -> list[tuple[int, int]]:
    """``(first, last)`` of each run of consecutive ``True`` in ``wanted``."""
    edges = np.diff(np.r_[0, wanted.astype(np.int8), 0])
    return list(
        zip(np.flatnonzero(edges == 1).tolist(), (np.flatnonzero(edges == -1) - 1).tolist(), strict=True)
    )
