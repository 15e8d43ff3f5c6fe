"""Acceleration caps local to where the moving average's jerk exceeds its limit.

The moving average of width ``w = a / j`` (:mod:`planning.curves.moving_average`) keeps a
joint's jerk within its limit wherever its acceleration changes by at most ``a`` within a
window. On a curved path the phase-plane profile's joints can swing from ``+a`` to ``-a``
at once (where the profile switches from accelerating to braking, or another joint's limit
takes over), and there the averaged jerk reaches ``2 j``. The timing's answers so far act on
the whole motion: a window widened everywhere (``jerk_limited_motion``), or a velocity cap
everywhere (:mod:`planning.curves.velocity_caps`). Here the window keeps its width and the
swinging joint's acceleration limit is lowered only on the stretch of path whose samples
enter the offending averages, by the jerk's excess there: each round re-solves the phase
plane with the lowered limits (as extra rows, each joint's scaled by the inverse of its cap
at each grid point), averages the motion again and lowers the limits where the jerk still
exceeds. Every round's motion is a valid candidate (its duration counts the uniform
stretch its remaining excess needs), and the shortest is kept.

Lowering an acceleration limit keeps the profile within every other limit, and the averages
keep velocity and acceleration within theirs; so the result is the timing's to check and
scale exactly like any capped motion.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit
from planning.curves.arc_length import ArcLengthPath
from planning.curves.moving_average import arc_at_times, averaged_motion, positions_at, scaled_duration
from planning.curves.phase_plane import phase_plane_profile, profile_instants
from planning.curves.torque_limits import phase_plane_rows

FloatArray = NDArray[np.float64]

LOCAL_ROUNDS = 10
"""Most rounds of lowering the limits where the jerk still exceeds."""
LOCAL_EXPONENT = 0.7
"""Each round divides a cap by the jerk's excess to this power: below 1, the caps come down
in smaller steps, and the rounds between give candidates (measured in ``docs/tuning.md``)."""


def locally_capped_motion(
    path: ArcLengthPath,
    limits: FloatArray,
    acceleration_cap: FloatArray,
    second_share: float,
    window_s: float,
    step_s: float,
    tolerance: float,
    *,
    shortest_s: float = np.inf,
    uncapped: FloatArray | None = None,
) -> tuple[float, FloatArray]:
    """The shortest motion of the rounds above, as ``(duration [s], motion (4, T, nj))``.

    The rounds stop once a round's profile, averaged, could not be shorter than ``shortest_s``
    [s] or than an earlier round's motion: each round lowers caps, so its profile is no faster
    than the last, and the averages add both windows (less the time grid's rounding). The
    duration is ``inf`` if no round was shorter than ``shortest_s``.

    Args:
        path: the path in arc length, with its torque rows if the timing keeps any.
        limits: ``(3, nj)`` velocity, acceleration and jerk limits of the phase plane and the
            averages.
        acceleration_cap: ``(nj,)`` the profile's acceleration limits before any is lowered.
        second_share: the second moving average's width as a share of the first.
        window_s: the first average's width [s], kept in every round.
        step_s: the time grid's step [s].
        tolerance: excess of the jerk limit left to the final uniform scaling.
        shortest_s: the shortest duration the caller has already [s].
        uncapped: the first round's profile (no limit lowered), if the caller has it.
    """
    caps = np.ones_like(path.dq)  # each joint's acceleration cap at each grid point, a share of its limit
    first = max(1, round(window_s / step_s))
    reach = first + max(1, round(second_share * window_s / step_s))  # an input sample's outputs
    best: tuple[float, FloatArray] = (np.inf, np.empty((4, 0, path.dq.shape[1])))
    for round_ in range(LOCAL_ROUNDS):
        x = (
            uncapped
            if round_ == 0 and uncapped is not None
            else _profile(path, limits[0], acceleration_cap, caps)
        )
        instants = profile_instants(x, path.ds)
        if instants[-1] + (1.0 + second_share) * window_s - 3.0 * step_s > min(shortest_s, best[0]):
            break
        s = arc_at_times(x, path.ds, step_s)
        positions = positions_at(s, path.length, path.table)
        motion = averaged_motion(positions, window_s, step_s, second_share)
        duration_s = scaled_duration(motion, step_s, *limits)
        if duration_s < min(shortest_s, best[0]):
            best = (duration_s, motion)
        usage = np.abs(motion[3]) / limits[2]
        if usage.max() <= 1.0 + tolerance:
            break
        cut = entering(
            np.where(usage > 1.0 + tolerance, np.maximum(usage, 1.0) ** -LOCAL_EXPONENT, 1.0), reach
        )
        at_grid = np.minimum(np.round(instants / step_s).astype(int), len(cut) - 1)
        caps *= cut[at_grid]
    return best


@njit
def entering(cut: FloatArray, reach: int) -> FloatArray:
    """For each input sample ``i``, the least of ``cut`` ``(T + reach, nj)`` over the outputs it enters.

    The averages' output at sample ``k`` averages the inputs ``k - reach .. k``, so input ``i``
    enters the outputs ``i .. i + reach`` (those that exist). Row ``i < T`` of the result is
    input ``i``'s. Van Herk and Gil-Werman's running minimum: blocks of ``reach + 1`` rows,
    each row's minimum from its block's start and to its block's end, so a window, which
    spans at most two blocks, is the lesser of two of them (a few operations per row, whatever
    ``reach``; compiled, where SciPy's ``minimum_filter1d`` cost its import in every process).
    """
    count, joints = cut.shape
    size = reach + 1
    result = np.empty_like(cut)
    from_start, to_end = np.empty_like(cut), np.empty_like(cut)
    for start in range(0, count, size):
        last = min(start + size, count) - 1
        from_start[start] = cut[start]
        for i in range(start + 1, last + 1):
            for j in range(joints):
                from_start[i, j] = min(from_start[i - 1, j], cut[i, j])
        to_end[last] = cut[last]
        for i in range(last - 1, start - 1, -1):
            for j in range(joints):
                to_end[i, j] = min(to_end[i + 1, j], cut[i, j])
    for start in range(0, count, size):  # each window: the end of its first block, the start of its next
        last = min(start + size, count) - 1
        for i in range(start, last + 1):
            end = min(i + reach, count - 1)
            for j in range(joints):
                result[i, j] = to_end[i, j] if end <= last else min(to_end[i, j], from_start[end, j])
    return result


def _profile(
    path: ArcLengthPath, velocity: FloatArray, acceleration: FloatArray, caps: FloatArray
) -> FloatArray:
    """The phase-plane profile, each joint's acceleration within ``caps`` of ``acceleration`` gridwise."""
    d1, d2, v, a, offset = phase_plane_rows(path.dq, path.ddq, velocity, acceleration, path.torque)
    lowered = np.flatnonzero(caps.min(axis=0) < 1.0)
    if lowered.size:
        inverse = 1.0 / caps[:, lowered]
        d1 = np.hstack([d1, path.dq[:, lowered] * inverse])
        d2 = np.hstack([d2, path.ddq[:, lowered] * inverse])
        offset = np.hstack([offset, np.zeros((len(inverse), lowered.size))])
        v = np.concatenate([v, np.full(lowered.size, np.inf)])
        a = np.concatenate([a, acceleration[lowered]])
    return phase_plane_profile(d1, d2, path.ds, v, a, offset)
