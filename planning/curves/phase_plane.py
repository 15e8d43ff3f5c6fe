"""Time-optimal path speed under velocity and acceleration limits (the phase-plane method).

A path ``q(u)`` with derivatives ``q'(u)``, ``q''(u)`` is followed at speed ``u'(t)``; with
``x = u'^2`` the joint velocity is ``q' sqrt(x)`` and the joint acceleration
``q'' x + q' x' / 2`` (``x'`` the derivative along ``u``). On a grid ``u_0 .. u_G`` the
fastest profile from rest to rest within ``|q_j'| u' <= v_j`` and ``|q_j'' u'^2 + q_j' u''| <= a_j``
lies under the *maximum velocity curve*: the largest ``x`` at which the velocity limits hold
and some acceleration satisfies every joint (exactly: every bound is affine in ``x``).

The time is ``sum 2 du / (sqrt(x_g) + sqrt(x_g+1))``. On each step the path acceleration is
constant and keeps the joints within their limits at the step's first grid point. As in
TOPP-RA (Pham and Pham 2018), a backward pass first finds at every grid point the largest
``x`` from which the end can still be reached (the controllable set); the forward pass then
accelerates as hard as it may without leaving it, so the profile never follows a limit
curve more steeply than the acceleration limits allow. The passes are compiled and batched
over many paths for the planner's fitness (:func:`sampled_path_times`, on the samples of
each candidate's path);
:mod:`planning.curves.path_timing` turns a profile into a jerk-limited, C3 septic trajectory.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit, njit_inline

FloatArray = NDArray[np.float64]

_TINY = 1e-12
_HUGE = 1e12


@njit_inline
def _acceleration_bounds(
    d1: FloatArray, d2: FloatArray, offset: FloatArray, g: int, x: float, a: FloatArray
) -> tuple[float, float]:
    """``(lowest, highest)`` path acceleration ``u''`` at grid point ``g`` and ``x = u'^2``.

    ``lowest > highest`` when no acceleration keeps every row within its limit.
    """
    low, high = -_HUGE, _HUGE
    for j in range(d1.shape[1]):
        slope, curve = d1[g, j], d2[g, j] * x + offset[g, j]
        if abs(slope) > _TINY:
            b1, b2 = (a[j] - curve) / slope, (-a[j] - curve) / slope
            high = min(high, max(b1, b2))
            low = max(low, min(b1, b2))
        elif abs(curve) > a[j]:
            return _HUGE, -_HUGE
    return low, high


@njit
def _row_bounds(
    d1: FloatArray, d2: FloatArray, offset: FloatArray, a: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``(slope, reach, shift)`` ``(G, R)``: row ``j`` allows ``u''`` in ``slope x + shift -+ reach``.

    ``slope = -q_j'' / q_j'``, ``reach = a_j / |q_j'|``, ``shift = -o_j / q_j'``; 0 where
    ``|q_j'| <= _TINY`` (the row is its curvature term alone, handled apart).
    """
    n, rows = d1.shape
    slope, reach, shift = np.zeros((n, rows)), np.zeros((n, rows)), np.zeros((n, rows))
    for g in range(n):
        for k in range(rows):
            if abs(d1[g, k]) > _TINY:
                slope[g, k] = -d2[g, k] / d1[g, k]
                reach[g, k] = a[k] / abs(d1[g, k])
                shift[g, k] = -offset[g, k] / d1[g, k]
    return slope, reach, shift


@njit_inline
def _largest_x(
    d1: FloatArray,
    d2: FloatArray,
    offset: FloatArray,
    bounds: tuple[FloatArray, FloatArray, FloatArray],
    g: int,
    a: FloatArray,
    top: float,
    du: float,
    ahead: float,
    rows_too: bool = True,
) -> float:
    """The largest ``x`` in ``[0, top]`` at grid point ``g`` that some path acceleration allows.

    That ``u''`` must keep every row within its limit and, if ``du > 0``, one step of ``du``
    (``u''`` constant, ``x_next = x + 2 du u''``) must land in ``[0, ahead]``. Without
    ``rows_too``, ``top`` is known to satisfy the rows' own bounds (it is at most the
    maximum velocity curve, their least), so only the step's are checked: the answer is the
    same, the rows' pairs (``R^2`` of them) skipped.

    Every bound on ``u''`` is affine in ``x``: row ``j`` allows ``u''`` in
    ``(-+a_j - q_j'' x - o_j) / q_j'`` (``bounds``, :func:`_row_bounds`), the step
    ``[-x, ahead - x] / (2 du)``. The bounds overlap iff every lower bound is below every
    upper bound (intervals on a line), each pair an affine inequality in ``x``: the answer is
    exact, the least of the pairs' limits, with no bisection. ``x = 0`` (``u'' = 0``)
    qualifies when every ``|o_j| <= a_j`` (the caller's condition), so the allowed ``x`` are
    an interval from 0.
    """
    slope, reach, shift = bounds
    best = top
    rows = d1.shape[1]
    rate = 1.0 / (2.0 * du) if du > 0.0 else 0.0
    for i in range(rows):
        if abs(d1[g, i]) <= _TINY:  # the row is the curvature term alone: |d2 x + o| <= a
            if rows_too and d2[g, i] > 0.0:
                best = min(best, (a[i] - offset[g, i]) / d2[g, i])
            elif rows_too and d2[g, i] < 0.0:
                best = min(best, (a[i] + offset[g, i]) / -d2[g, i])
            continue
        slope_i, reach_i, shift_i = slope[g, i], reach[g, i], shift[g, i]
        for k in range(rows if rows_too else 0):
            if k != i and abs(d1[g, k]) > _TINY and slope_i - slope[g, k] > 0.0:  # i low < k high
                best = min(best, (reach_i + reach[g, k] + (shift[g, k] - shift_i)) / (slope_i - slope[g, k]))
        if du > 0.0:
            if slope_i + rate > 0.0:  # lower of i below the step's upper (ahead - x) rate
                best = min(best, (ahead * rate + reach_i - shift_i) / (slope_i + rate))
            if -rate - slope_i > 0.0:  # the step's lower -x rate below the upper of i
                best = min(best, (reach_i + shift_i) / (-rate - slope_i))
    return max(best, 0.0)


@njit
def phase_plane_profile(
    d1: FloatArray, d2: FloatArray, du: FloatArray, v: FloatArray, a: FloatArray, offset: FloatArray
) -> FloatArray:
    """``x = u'^2`` at the grid points ``(G,)`` of the fastest rest-to-rest profile.

    Each of the ``R`` rows (a joint's acceleration, or a torque) keeps
    ``|d1 u'' + d2 u'^2 + offset| <= a`` and its velocity ``|d1| u' <= v``.

    Args:
        d1: ``(G, R)`` path derivative ``q'(u)`` at the grid points (a torque's ``M q'``).
        d2: ``(G, R)`` second derivative ``q''(u)`` (a torque's ``M q'' + C(q, q') q'``).
        du: ``(G - 1,)`` grid steps.
        v: ``(R,)`` velocity limits [rad/s, m/s] (``inf`` for a torque).
        a: ``(R,)`` acceleration limits (a torque's effort limit).
        offset: ``(G, R)`` the part that does not depend on the speed (0, or gravity's
            torque), each within its limit.
    """
    n, rows = d1.shape
    bounds = _row_bounds(d1, d2, offset, a)
    limit = np.empty(n)
    for g in range(n):  # the maximum velocity curve: velocity limits, then accelerations
        top = _HUGE
        for j in range(rows):
            if abs(d1[g, j]) > _TINY:
                top = min(top, (v[j] / abs(d1[g, j])) ** 2)
        limit[g] = _largest_x(d1, d2, offset, bounds, g, a, top, 0.0, 0.0)
    controllable = np.zeros(n)  # backward: from where the robot can still stop at the end
    for g in range(n - 2, -1, -1):
        controllable[g] = _largest_x(  # limit[g] holds the rows' bounds: only the step's are new
            d1, d2, offset, bounds, g, a, limit[g], du[g], controllable[g + 1], False
        )
    x = np.zeros(n)  # forward: as fast as the limits allow without leaving the controllable set
    for g in range(n - 1):
        _, high = _acceleration_bounds(d1, d2, offset, g, x[g], a)
        x[g + 1] = max(min(controllable[g + 1], x[g] + 2.0 * du[g] * high), 0.0)
    return x


@njit
def profile_instants(x: FloatArray, du: FloatArray) -> FloatArray:
    """``(G,)`` instants [s] at which the profile ``x = u'^2`` reaches its grid points (steps ``du``).

    The path acceleration is constant on each step, so a step takes ``2 du / (u'_g + u'_g+1)``.
    """
    instants = np.zeros(len(x))
    for g in range(len(x) - 1):
        instants[g + 1] = instants[g] + 2.0 * du[g] / max(np.sqrt(x[g]) + np.sqrt(x[g + 1]), _TINY)
    return instants


def path_acceleration(x: FloatArray, du: FloatArray) -> FloatArray:
    """``(G,)`` the path acceleration ``u''`` of profile ``x`` on each step (from its first point), 0 last."""
    return np.append(np.diff(x) / (2.0 * du), 0.0)


@njit
def profile_time(x: FloatArray, du: FloatArray) -> float:
    """Duration [s] of the profile ``x = u'^2`` on a grid of steps ``du`` ``(G - 1,)``."""
    return float(profile_instants(x, du)[-1])


@njit
def kept_samples(points: FloatArray, v: FloatArray) -> NDArray[np.int64]:
    """Indices of the samples ``(M,)`` of a path ``(count, nj)`` farther than ``1e-9`` from the one before.

    Distances in seconds at the velocity limits ``v``; the first sample is always kept.
    """
    count, joints = points.shape
    index = np.empty(count, dtype=np.int64)
    index[0] = 0
    m = 1
    for k in range(1, count):
        step = 0.0
        for j in range(joints):
            step += ((points[k, j] - points[index[m - 1], j]) / v[j]) ** 2
        if np.sqrt(step) > 1e-9:
            index[m] = k
            m += 1
    return index[:m]


@njit
def sampled_derivatives(points: FloatArray, v: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Arc-length steps ``(M - 1,)`` and ``dq/ds``, ``d2q/ds2`` ``(M, nj)`` of a sampled path.

    ``s`` measures each joint in seconds at its velocity limit; samples closer than ``1e-9``
    to the one before are dropped (:func:`kept_samples`); derivatives are the three-point
    formulas of a non-uniform grid, taken from the neighbour at the ends.
    """
    return kept_derivatives(points, kept_samples(points, v), v)


@njit
def kept_derivatives(
    points: FloatArray, index: NDArray[np.int64], v: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """:func:`sampled_derivatives` at the samples ``index`` that :func:`kept_samples` keeps.

    For a caller that needs those samples too: they are found once.
    """
    joints = points.shape[1]
    kept = points[index]
    m = kept.shape[0]
    steps = np.empty(max(m - 1, 1))
    steps[0] = 1.0
    for k in range(m - 1):
        step = 0.0
        for j in range(joints):
            step += ((kept[k + 1, j] - kept[k, j]) / v[j]) ** 2
        steps[k] = np.sqrt(step)
    d1 = np.zeros((max(m, 2), joints))
    d2 = np.zeros((max(m, 2), joints))
    for k in range(1, m - 1):
        h1, h2 = steps[k - 1], steps[k]
        for j in range(joints):
            f0, f1, f2 = kept[k - 1, j], kept[k, j], kept[k + 1, j]
            d1[k, j] = -h2 / (h1 * (h1 + h2)) * f0 + (h2 - h1) / (h1 * h2) * f1 + h1 / (h2 * (h1 + h2)) * f2
            d2[k, j] = 2.0 * (f0 / (h1 * (h1 + h2)) - f1 / (h1 * h2) + f2 / (h2 * (h1 + h2)))
    if m >= 3:
        d1[0], d1[m - 1], d2[0], d2[m - 1] = d1[1], d1[m - 2], d2[1], d2[m - 2]
    elif m == 2:
        for j in range(joints):
            d1[0, j] = d1[1, j] = (kept[1, j] - kept[0, j]) / steps[0]
    return steps, d1[:m], d2[:m]


@njit
def sampled_path_times(points: FloatArray, v: FloatArray, a: FloatArray) -> FloatArray:
    """``(S,)`` fastest rest-to-rest durations [s] along ``S`` sampled paths ``(S, M, nj)``.

    The paths are taken in arc length (:func:`sampled_derivatives`): a path that creeps
    in its own parameter (as a rest-to-rest spline does near its ends) is not mistaken for
    one that moves fast.
    """
    times = np.zeros(points.shape[0])
    for s in range(points.shape[0]):
        steps, d1, d2 = sampled_derivatives(points[s], v)
        if len(d1) >= 2:
            times[s] = profile_time(phase_plane_profile(d1, d2, steps, v, a, np.zeros_like(d1)), steps)
    return times
