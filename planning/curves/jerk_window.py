"""How long a phase-plane profile takes once its jerk is limited: the fitness's duration estimate.

:func:`~planning.curves.path_timing.time_path` runs each joint's motion along the
phase-plane profile through two moving averages, of widths ``w`` and ``r w`` (``r``, the
second share, :func:`~planning.curves.path_timing.smoothing_limits`), starting at
``w = max_j a_j / j_j``, and widens ``w`` while the averaged jerk exceeds its limit
(:func:`~planning.curves.moving_average.jerk_limited_motion`); the motion lasts the
profile's time plus ``(1 + r) w``. Where a joint switches from accelerating to braking at
once (a move too short to cruise), its acceleration swings by ``2 a`` and the window
doubles, so the constant allowance ``(1 + r) a / j`` of the narrowest window underestimates
such paths by as much again.

This module repeats the widening on the profile itself. The two averages' jerk is a
difference of the joint's velocity ``v`` at four instants (the averages of an acceleration
are differences of its integral)::

    jerk(t) = (v(t) - v(t - r w) - v(t - w) + v(t - (1 + r) w)) / (r w^2)

With ``v`` linear between the profile's grid points, its extrema lie where one of the four
instants meets a grid point, so a few hundred evaluations give it exactly, without the
timing's fine time grid. :func:`sampled_path_durations` is the batch the fitness calls.
Not modelled: the timing's velocity caps, which sometimes trade a wider window for a short
cruise (:mod:`planning.curves.velocity_caps`); there the estimate lies above the timing.
How close the estimate comes, and why the caps are left out: ``docs/tuning.md``.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit
from planning.curves.phase_plane import phase_plane_profile, profile_instants, sampled_derivatives

FloatArray = NDArray[np.float64]

SIGNS = (1.0, -1.0, -1.0, 1.0)
"""The signs of the averaged jerk's four velocities (module docstring)."""
SAMPLED_SECOND_SHARE = 0.25
"""The least second share with which :func:`profile_window` checks the jerk of a
sampled path: the fitness knows a path at a few dozen samples, between which its velocity
bends at kinks the timing's fine table does not have; a narrower second average would widen
windows for them that the timing does not (measured in ``docs/tuning.md``)."""


@njit
def averaged_jerk_usage(
    times: FloatArray, velocity: FloatArray, jerk: FloatArray, window_s: float, second_share: float
) -> float:
    """Largest ``|jerk| / limit`` of the two averages of width ``window_s`` and ``second_share`` of it.

    Args:
        times: ``(G,)`` increasing instants of the profile's grid [s], from rest to rest.
        velocity: ``(G, nj)`` joint velocities there [rad/s, m/s].
        jerk: ``(nj,)`` jerk limits.
        window_s: the first average's width [s], > 0.
        second_share: the second average's width as a share of ``window_s``, in (0, 1].

    The jerk is checked where one of its four velocities meets a grid point: at each of the
    four breakpoints, each term reads the velocity at the grid's instants shifted by the
    breakpoint's delay less its own. Of those 16 shifts, the four of a term at its own
    breakpoint are 0 and others coincide (with a second share of a quarter, 9 are distinct),
    so each distinct shift's velocities are interpolated once.
    """
    count, joints = velocity.shape
    scale = 1.0 / (second_share * window_s**2)
    delays = (0.0, second_share, 1.0, 1.0 + second_share)  # of the four velocities, shares of the window
    offsets = np.empty(16)
    slot = np.empty(16, dtype=np.int64)  # the distinct shift that term t reads at breakpoint b: 4 b + t
    distinct = 0
    for b in range(4):
        for term in range(4):
            offset = (delays[b] - delays[term]) * window_s
            slot[4 * b + term] = distinct
            for i in range(distinct):
                if offsets[i] == offset:
                    slot[4 * b + term] = i
                    break
            if slot[4 * b + term] == distinct:
                offsets[distinct] = offset
                distinct += 1
    shifted = np.zeros((distinct, count, joints))  # the velocity at times[g] + offsets[i]
    for i in range(distinct):
        k = 0  # the grid interval of times[g] + offset, increasing with g
        for g in range(count):
            t = times[g] + offsets[i]
            if t <= times[0] or t >= times[-1]:
                continue  # at rest before the start and after the end
            while times[k + 1] < t:
                k += 1
            share = (t - times[k]) / max(times[k + 1] - times[k], 1e-300)
            for j in range(joints):
                shifted[i, g, j] = velocity[k, j] + share * (velocity[k + 1, j] - velocity[k, j])
    peak = np.zeros(joints)  # the largest |averaged jerk| * r w^2 of each joint
    for b in range(4):
        first, second, third, fourth = (
            shifted[slot[4 * b]],
            shifted[slot[4 * b + 1]],
            shifted[slot[4 * b + 2]],
            shifted[slot[4 * b + 3]],
        )
        for g in range(count):
            for j in range(joints):
                averaged = 0.0  # the terms in order, as a sum from zero
                averaged += SIGNS[0] * first[g, j]
                averaged += SIGNS[1] * second[g, j]
                averaged += SIGNS[2] * third[g, j]
                averaged += SIGNS[3] * fourth[g, j]
                peak[j] = max(peak[j], abs(averaged))
    usage = 0.0
    for j in range(joints):
        usage = max(usage, peak[j] * scale / jerk[j])
    return usage


@njit
def needed_window(
    times: FloatArray,
    velocity: FloatArray,
    jerk: FloatArray,
    window_s: float,
    rounds: int,
    tolerance: float,
    second_share: float,
) -> tuple[float, float]:
    """The window the timing ends with, and its jerk usage (the widenings of ``jerk_limited_motion``).

    Each of at most ``rounds`` widenings multiplies the window by the usage (at most 2) while
    the usage exceeds ``1 + tolerance``.
    """
    usage = averaged_jerk_usage(times, velocity, jerk, window_s, second_share)
    for _ in range(rounds):
        if usage <= 1.0 + tolerance:
            break
        window_s *= min(usage, 2.0)
        usage = averaged_jerk_usage(times, velocity, jerk, window_s, second_share)
    return window_s, usage


@njit
def sampled_path_durations(
    points: FloatArray,
    v: FloatArray,
    a: FloatArray,
    j: FloatArray,
    window_s: float,
    rounds: int,
    tolerance: float,
    second_share: float,
) -> FloatArray:
    """``(S,)`` durations [s] of the jerk-limited motions along ``S`` sampled paths ``(S, M, nj)``.

    The phase-plane time under the velocity and acceleration limits ``v``, ``a``
    (:func:`~planning.curves.phase_plane.sampled_path_times`), plus ``1 + second_share`` times the
    window :func:`needed_window` widens to for the jerk limits ``j`` from ``window_s`` (the
    timing's ``max a / j`` over all the robot's joints) [s], stretched by ``usage^(1/3)``
    where the last window still exceeds the jerk limit (as the timing's final uniform
    scaling does).
    """
    durations = np.zeros(points.shape[0])
    for s in range(points.shape[0]):
        steps, d1, d2 = sampled_derivatives(points[s], v)
        if len(d1) < 2:
            continue
        x = phase_plane_profile(d1, d2, steps, v, a, np.zeros_like(d1))
        times, window, usage = profile_window(x, steps, d1, j, window_s, rounds, tolerance, second_share)
        durations[s] = jerk_limited_duration(times, window, usage, second_share)
    return durations


@njit
def jerk_limited_duration(times: FloatArray, window_s: float, usage: float, second_share: float) -> float:
    """Duration [s] of a profile reaching its grid points at ``times`` once its jerk is limited.

    The profile's time plus ``1 + second_share`` times the window ``window_s`` its jerk
    needs, stretched by ``usage^(1/3)`` where that window still exceeds the jerk limit
    (:func:`profile_window` gives all three).
    """
    return float((times[-1] + (1.0 + second_share) * window_s) * max(1.0, usage ** (1.0 / 3.0)))


@njit
def profile_window(
    x: FloatArray,
    steps: FloatArray,
    d1: FloatArray,
    j: FloatArray,
    window_s: float,
    rounds: int,
    tolerance: float,
    second_share: float,
) -> tuple[FloatArray, float, float]:
    """When the profile ``x`` reaches its grid points [s], the window it ends with [s], its jerk usage.

    ``x`` on path steps ``steps`` with ``dq/ds`` ``d1``; the window is the one
    :func:`needed_window` widens to from ``window_s`` for the jerk limits ``j``, the jerk
    checked with a second share of at least :data:`SAMPLED_SECOND_SHARE`.
    """
    times = profile_instants(x, steps)
    velocity = d1 * np.sqrt(np.maximum(x, 0.0))[:, None]
    checked = max(second_share, SAMPLED_SECOND_SHARE)
    window, usage = needed_window(times, velocity, j, window_s, rounds, tolerance, checked)
    return times, window, usage
