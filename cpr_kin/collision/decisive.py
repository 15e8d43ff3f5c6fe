"""Which samples of a certified curve check must be exact for its minima to be exact.

A certified check samples a curve at ``K`` instants and reports, per column (a group of
pairs), the smallest certified value ``(c_k + c_{k+1} - slack_k) / 2`` over the intervals and
the smallest sampled value. Where a cheap lower bound of ``c_k`` is known, only the samples
whose exact value could still lower one of those minima need coal: :func:`undecided` names
them, and a check computes them and asks again until none is left. Values computed from lower
bounds are at most the true ones, so a minimum found from exact values is the true minimum.

A check's caller may stop it before its verdict (a plan past its time limit): the check asks
its ``stop`` (:data:`Stop`) between its pieces of work (:func:`ask`, :func:`chunked`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, overload

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.errors import CheckStoppedError

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

Stop = Callable[[], bool]
"""Asked between a certified check's pieces of work: ``True`` stops it (:class:`CheckStoppedError`)."""
CHUNK_ROWS = 256
"""Configurations a stoppable check gives coal in one call (:func:`chunked`): a few tenths of a
second at most, on meshes of thousands of triangles."""

COARSE_STRIDE = 8
"""Of the samples in doubt, every how many coal computes first (:func:`first_rows`): its exact
values bound their neighbours' (a distance changes no faster than the robot moves), which may
then need none."""
COARSE_BELOW = 64
"""Fewer samples in doubt than this are computed at once (another round costs more than they)."""

COAL_RELATIVE_ERROR = 1e-6
"""How far coal's distance may fall below the truth, relative to its size (coal's distances are
accurate to about 1e-6 of their size; below a metre, to 1e-6 m): :func:`coal_error_m`."""


@overload
def coal_error_m(distance_m: float) -> float: ...


@overload
def coal_error_m(distance_m: FloatArray) -> FloatArray: ...


def coal_error_m(distance_m: float | FloatArray) -> float | FloatArray:
    """Coal's error at ``distance_m`` [m]: :data:`COAL_RELATIVE_ERROR` of ``max(1 m, |distance|)``.

    A configuration goes to coal unless its bounds clear a margin by this much, and a bound
    rules a pair out, or stands for coal's value, only less this much. A float gives a float
    (a test's margin, asked at every call of the margin tests), an array an array.
    """
    if isinstance(distance_m, float):
        return COAL_RELATIVE_ERROR * max(1.0, abs(distance_m))
    return np.asarray(COAL_RELATIVE_ERROR * np.maximum(1.0, np.abs(distance_m)))


def below_coal(bounds_m: FloatArray) -> FloatArray:
    """``bounds_m`` [m] less coal's error at their size: at most coal's value where they bound the truth."""
    return np.asarray(bounds_m - coal_error_m(bounds_m))


def certified(values: FloatArray, slack_m: float | FloatArray) -> FloatArray:
    """``(c_k + c_{k+1} - slack_k) / 2`` per interval: the least the distance can be between samples.

    ``values`` ``(K,)`` or ``(K, G)`` [m]; ``slack_m`` one value, one per interval ``(K - 1,)``
    (for every column) or ``(K - 1, G)`` [m].
    """
    slack = np.asarray(slack_m, dtype=float)
    if slack.ndim == 1 and values.ndim == 2:
        slack = slack[:, None]
    return np.asarray(0.5 * (values[:-1] + values[1:] - slack))


def exact_below(margin_m: float, slack_m: float | FloatArray) -> float:
    """The value [m] below which a certified check of ``margin_m`` [m] needs its samples exact.

    A sample at or above the margin plus the largest slack of an interval (``slack_m``) [m]
    certifies both its intervals whatever its neighbours above the margin are: counted as that
    value, a lower bound, it decides the check the same.
    """
    return margin_m + float(np.max(slack_m, initial=0.0))


def undecided(
    values: FloatArray,
    known: NDArray[np.bool_],
    slack_m: float | FloatArray,
    certified_ceiling_m: float = np.inf,
    sampled_ceiling_m: float = np.inf,
) -> NDArray[np.bool_]:
    """``(K, G)`` samples not yet exact whose exact value could still lower a minimum the check reports.

    Args:
        values: ``(K, G)`` sampled values [m], exact where ``known``, lower bounds elsewhere.
        known: ``(K, G)`` which values are exact.
        slack_m: the certified bound's slack, one value or one per interval ``(K - 1,)`` [m].
        certified_ceiling_m: a certified value the check has found elsewhere [m]: no value
            at or above it can lower the certified minimum.
        sampled_ceiling_m: the same for the smallest sampled value [m].
    """
    needed = np.zeros_like(known)
    lower = certified(values, slack_m)
    both_known = known[:-1] & known[1:]
    for g in range(values.shape[1]):
        column = lower[:, g]
        lowest = int(np.argmin(column))
        if both_known[lowest, g] or column[lowest] >= certified_ceiling_m:
            continue
        best_exact = min(float(np.min(column[both_known[:, g]], initial=np.inf)), certified_ceiling_m)
        below = column <= best_exact if np.isfinite(best_exact) else np.arange(len(column)) == lowest
        needed[:-1, g] |= below
        needed[1:, g] |= below
    lowest_sample = np.unravel_index(int(np.argmin(values)), values.shape)
    if not known[lowest_sample] and values[lowest_sample] < sampled_ceiling_m:
        best_exact = min(float(np.min(values[known], initial=np.inf)), sampled_ceiling_m)
        if np.isfinite(best_exact):
            needed |= values <= best_exact
        else:
            needed[lowest_sample] = True
    return needed & ~known


def first_rows(rows: IntArray, coarse_from: int = COARSE_BELOW) -> IntArray:
    """Of the samples in doubt ``rows`` (increasing), those coal computes in a check's next round.

    Every :data:`COARSE_STRIDE`-th where ``coarse_from`` or more are in doubt, else all; the
    check then bounds the others by :func:`with_neighbours` and asks :func:`undecided` again.
    A round of every pair's distances (a group's clearance) is dear: each takes a share where
    :data:`COARSE_BELOW` or more are in doubt. One pair's round is cheap but its doubt sits in
    short runs: its first round takes a share of even a few (``coarse_from=1``), the later
    rounds all that are left (``docs/tuning.md``, Kernels).
    """
    return rows[:: COARSE_STRIDE if rows.size >= coarse_from else 1]


def propagated_bounds(values: FloatArray, known: NDArray[np.bool_], reach_m: FloatArray) -> FloatArray:
    """``(K,)`` lower bounds of a sampled distance from its exact values at the ``known`` samples.

    ``reach_m`` ``(K,)`` is cumulative: between samples ``i < j`` the distance changes by at
    most ``reach_m[j] - reach_m[i]`` [m]. Each sample gets the best bound any exact sample
    gives it (``-inf`` with none); the exact values are kept.
    """
    left = np.maximum.accumulate(np.where(known, values + reach_m, -np.inf)) - reach_m
    right = np.maximum.accumulate(np.where(known, values - reach_m, -np.inf)[::-1])[::-1] + reach_m
    return np.asarray(np.where(known, values, np.maximum(left, right)))


def with_neighbours(
    values: FloatArray, known: NDArray[np.bool_], bounds: FloatArray, reach_m: FloatArray
) -> FloatArray:
    """``(K,)`` a sampled distance: exact at the ``known`` samples, else the best lower bound there is.

    Elsewhere the larger of the cheap bound (``bounds``) and what the exact samples give
    (:func:`propagated_bounds`), the latter less coal's error (:func:`below_coal`: how far the
    exact values may be above the true ones). Every certified check updates its samples by this rule.
    """
    propagated = below_coal(propagated_bounds(values, known, reach_m))
    return np.asarray(np.where(known, values, np.maximum(bounds, propagated)))


def ask(stop: Stop | None) -> None:
    """Raise :class:`CheckStoppedError` where ``stop`` says so (never for ``None``)."""
    if stop is not None and stop():
        raise CheckStoppedError("the certified check was stopped by its caller before its verdict")


def chunked(
    function: Callable[[NDArray[Any]], Any], q: NDArray[Any], stop: Stop | None, rows: int = CHUNK_ROWS
) -> Any:
    """``function(q)`` computed ``rows`` configurations at a time, ``stop`` asked before each (:func:`ask`).

    ``function`` takes configurations ``(N, nq)`` (or their indices ``(N,)``) and returns an
    array or a tuple of arrays, one row per configuration, each row its configuration's alone:
    the pieces are joined as one call would return them. Without ``stop``, one call.
    """
    ask(stop)
    if stop is None or len(q) <= rows:
        return function(q)
    parts = [function(q[:rows])]
    for first in range(rows, len(q), rows):
        ask(stop)
        parts.append(function(q[first : first + rows]))
    if isinstance(parts[0], tuple):
        return tuple(np.concatenate(column) for column in zip(*parts, strict=True))
    return np.concatenate(parts)
