"""Jerk limiting by moving averages (the "FIR" interpolation of CNC controllers), compiled.

A motion sampled every ``step_s`` whose velocity and acceleration are within their limits
keeps them under a moving average: an average of values within a bound is within it. The
jerk of the averaged motion is the change of its acceleration over the window, at most
``a / w`` for a window of ``w`` seconds: a window of ``w = a / j`` turns a velocity- and
acceleration-limited profile into a jerk-limited one, and the motion ends ``w`` later
(Tajima and Sencer 2016, "Kinematic corner smoothing for high speed machine tools"). A
second, narrower average (``second_share`` of ``w``) rounds the jerk's own steps, so the
septic through samples of the motion does not overshoot them.
:mod:`planning.curves.path_timing` uses these kernels on the phase-plane profile of a path.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit
from planning.curves.phase_plane import profile_instants, profile_time
from planning.errors import NoSolutionError

FloatArray = NDArray[np.float64]


LONGEST_MOTION_S = 3600.0
"""Longest motion along a path that is sampled [s]: a profile slower than this stops (or all but
stops) somewhere inside the path, at a point it can pass only at rest (a corner)."""


def arc_at_times(x: FloatArray, ds: FloatArray, step_s: float) -> FloatArray:
    """Arc length ``s`` every ``step_s`` along a phase-plane profile, and at its end.

    Args:
        x: ``(G,)`` squared path speed ``s'^2`` at the grid points.
        ds: ``(G - 1,)`` grid steps.
        step_s: time step [s].

    Between grid points the path acceleration ``s''`` is constant, so ``s(t)`` is exact.

    Raises:
        NoSolutionError: the profile takes more than :data:`LONGEST_MOTION_S` (its samples
            would not fit in memory; the path cannot be passed without stopping inside it).
    """
    total_s = profile_time(x, ds)
    if not total_s <= LONGEST_MOTION_S:
        raise NoSolutionError(
            f"the path cannot be timed: at the limits it takes {total_s:.3g} s, more than "
            f"{LONGEST_MOTION_S:g} s (it stops inside, at a point it can pass only at rest, such as a corner)"
        )
    return _arc_at_times(x, ds, step_s)


@njit
def _arc_at_times(x: FloatArray, ds: FloatArray, step_s: float) -> FloatArray:
    """:func:`arc_at_times`, compiled."""
    count = len(x)
    speed = np.sqrt(np.maximum(x, 0.0))
    starts = profile_instants(x, ds)  # time at each grid point
    total = starts[-1]
    samples = int(np.ceil(total / step_s - 1e-12)) + 1
    s = np.empty(samples)
    grid = 0.0
    g = 0
    for k in range(samples):
        t = min(k * step_s, total)
        while g < count - 2 and starts[g + 1] <= t:
            grid += ds[g]
            g += 1
        tau = t - starts[g]
        push = (x[g + 1] - x[g]) / (2.0 * ds[g])
        s[k] = grid + speed[g] * tau + 0.5 * push * tau * tau
    length = 0.0
    for g in range(count - 1):
        length += ds[g]
    return np.minimum(s, length)


@njit
def positions_at(s: FloatArray, length: FloatArray, table: FloatArray) -> FloatArray:
    """``(T, nj)`` the path's positions at the non-decreasing arc lengths ``s`` ``(T,)``.

    Linear between the path's fine samples ``table`` ``(F, nj)`` at the increasing arc lengths
    ``length`` ``(F,)``, held beyond them: ``numpy.interp`` of each column, in one pass.
    """
    count, joints = len(s), table.shape[1]
    out = np.empty((count, joints))
    k = 0
    for i in range(count):
        while k < len(length) - 2 and length[k + 1] < s[i]:
            k += 1
        span = length[k + 1] - length[k]
        share = min(max((s[i] - length[k]) / span, 0.0), 1.0) if span > 0.0 else 0.0
        for j in range(joints):
            out[i, j] = table[k, j] + share * (table[k + 1, j] - table[k, j])
    return out


@njit
def _average(values: FloatArray, width: int) -> FloatArray:
    """Moving average over ``width`` samples along axis 0, ``width`` samples longer.

    Before and after the motion the robot stands at its first and last position, so the
    first output is the first position and the last the last.
    """
    count, joints = values.shape
    out = np.empty((count + width, joints))
    for j in range(joints):
        total = values[0, j] * width  # the window over the samples padded before
        for k in range(count + width):
            out[k, j] = total / width
            enter = values[min(k, count - 1), j]
            leave = values[max(k - width, 0), j] if k >= width else values[0, j]
            total += enter - leave
    return out


@njit
def _gradient(values: FloatArray, step_s: float) -> FloatArray:
    """``numpy.gradient`` along axis 0: central differences, one-sided at both ends."""
    count, joints = values.shape
    out = np.zeros_like(values)
    if count < 2:
        return out
    for j in range(joints):  # element by element: row slices would allocate
        out[0, j] = (values[1, j] - values[0, j]) / step_s
        out[count - 1, j] = (values[count - 1, j] - values[count - 2, j]) / step_s
        for k in range(1, count - 1):
            out[k, j] = (values[k + 1, j] - values[k - 1, j]) / (2.0 * step_s)
    return out


@njit
def averaged_motion(positions: FloatArray, window_s: float, step_s: float, second_share: float) -> FloatArray:
    """``(4, T', nj)`` position, velocity, acceleration and jerk of the averaged positions.

    The positions ``(T, nj)`` every ``step_s`` are averaged over ``window_s``, then over
    ``second_share`` of it. The derivatives are central differences of the averaged positions
    themselves: the Hermite data a septic takes from them must agree with each other, or
    small disagreements become large jerks over a short segment.
    """
    first = max(1, round(window_s / step_s))
    second = max(1, round(second_share * window_s / step_s))
    smooth = _average(_average(positions, first), second)
    out = np.empty((4, smooth.shape[0], smooth.shape[1]))
    out[0] = smooth
    for r in range(1, 4):
        out[r] = _gradient(out[r - 1], step_s)
    return out


@njit
def jerk_limited_motion(
    positions: FloatArray,
    window_s: float,
    step_s: float,
    jerk: FloatArray,
    rounds: int,
    tolerance: float,
    second_share: float,
) -> tuple[FloatArray, float]:
    """:func:`averaged_motion` with the window widened until the jerk is within ``1 + tolerance``.

    A profile that switches from accelerating to braking at once (a move too short to
    cruise) needs more than ``a / j`` to ramp through the switch; each of at most ``rounds``
    widenings multiplies the window by the jerk's excess (at most 2). Returns the motion
    and the window it took [s].
    """
    motion = averaged_motion(positions, window_s, step_s, second_share)
    for _ in range(rounds):
        usage = 0.0
        for k in range(motion.shape[1]):
            for j in range(motion.shape[2]):
                usage = max(usage, abs(motion[3, k, j]) / jerk[j])
        if usage <= 1.0 + tolerance:
            break
        window_s *= min(usage, 2.0)
        motion = averaged_motion(positions, window_s, step_s, second_share)
    return motion, window_s


@njit
def scaled_duration(motion: FloatArray, step_s: float, v: FloatArray, a: FloatArray, j: FloatArray) -> float:
    """Duration [s] of ``motion`` once uniformly scaled in time to meet every limit at its samples."""
    usage = np.zeros(3)
    for k in range(motion.shape[1]):
        for n in range(motion.shape[2]):
            usage[0] = max(usage[0], abs(motion[1, k, n]) / v[n])
            usage[1] = max(usage[1], abs(motion[2, k, n]) / a[n])
            usage[2] = max(usage[2], abs(motion[3, k, n]) / j[n])
    worst = max(1.0, usage[0], np.sqrt(usage[1]), usage[2] ** (1.0 / 3.0))
    return float((motion.shape[1] - 1) * step_s * worst)
