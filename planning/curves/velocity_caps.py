"""The fastest jerk-limited motion along a path, over caps of its phase-plane profile.

Steps 1 and 2 of :mod:`planning.curves.path_timing` for one pair of caps
(:func:`capped_motion`): the phase-plane profile of the path under a velocity cap and an
acceleration cap, then each joint's motion along it through the moving averages that bring
its jerk within the limit. :func:`fastest_motion` searches the caps for the shortest
motion once uniformly scaled to meet every limit.

Why caps: a move too short to cruise switches from accelerating to braking at once, and the
moving average needs a wider window to ramp through that switch within the jerk limit.
Cruising briefly below the peak, long enough for the acceleration to ramp down and up apart,
is often faster; so, on curved paths, can a cap that changes where the profile brakes.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from planning.curves.arc_length import ArcLengthPath
from planning.curves.local_caps import locally_capped_motion
from planning.curves.moving_average import arc_at_times, jerk_limited_motion, positions_at, scaled_duration
from planning.curves.phase_plane import path_acceleration, phase_plane_profile, profile_time
from planning.curves.torque_limits import phase_plane_rows

FloatArray = NDArray[np.float64]

STEPS_PER_RAMP = 100
"""Steps of the time grid on which the joints' motion is averaged, per ``max_j a_j / j_j``
(the time the jerk limit takes to ramp the acceleration limit). Relative,
so that limits scaled as time is (``v`` by ``k``, ``a`` by ``k^2``, ``j`` by ``k^3``) give the
same motion ``k`` times faster."""
ROUNDS = 3
"""Most widenings of the averaging window for a jerk beyond the limit."""
TOLERANCE = 0.02
"""Excess of the jerk limit left to the final uniform scaling."""
FACTORS = (0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.65, 0.6, 0.55, 0.5, 0.45, 0.4, 0.35, 0.3)
"""Caps of the phase-plane profile's velocity tried, as shares of its uncapped peak.

The duration is not monotone in the cap (it jumps where the window must widen), so a grid is
tried, refined by bisection where the widening stops. Shares of the peak rather than of
the limit keep the search the same when a limit that does not bind is raised."""
RAMP_FACTORS = (0.75, 0.5)
"""Shares of the best velocity cap's acceleration ramp time tried as caps of the ramps."""
BISECTIONS = 4
"""Bisection steps between two neighbours of the grid (each halves the interval)."""
MARGIN = 0.01
"""How far below the bisection's boundary the cap is taken, as a share of the peak."""


class CappedMotion(NamedTuple):
    """The motion that one pair of caps gives (:func:`capped_motion`)."""

    duration_s: float
    """Its duration once uniformly scaled to meet every limit at its samples [s]."""
    widened: bool
    """The moving average needed a wider window than the accelerations' ramps."""
    peak: float
    """The profile's largest velocity as a share of the limit."""
    window_s: float
    """The moving average's width the profile's accelerations need [s]."""
    motion: FloatArray
    """Position, velocity, acceleration and jerk every ``step_s`` ``(4, T, nj)``."""
    step_s: float
    """The motion's time step [s]."""


def fastest_motion(
    path: ArcLengthPath, limits: FloatArray, second_share: float, uncapped: FloatArray | None = None
) -> CappedMotion:
    """The fastest motion along ``path`` over the caps of :data:`FACTORS` and :data:`RAMP_FACTORS`.

    ``limits`` ``(3, nj)``: velocity, acceleration and jerk limits; ``second_share``: the
    second moving average's width as a share of the first's. The uncapped profile
    first, then velocity caps at :data:`FACTORS` of its peak (above the peak a cap changes
    nothing); between the first pair of neighbours where the window stops widening, the
    largest cap that needs no wider window, found by bisection and taken :data:`MARGIN`
    lower (the jerk rises steeply past it); last, caps on the accelerations' ramps at the
    best velocity cap. ``uncapped``: the uncapped profile, if the caller has it.

    The grid stops at the first cap whose phase-plane time exceeds the best duration so far:
    a lower cap only slows the profile, and the averages add to it, so no cap below can win.
    A cap whose :func:`duration_lower_bound` exceeds the best is not averaged where its
    window's widening decides nothing (after the bisection, the bisection's last cap, the
    ramps' caps). The result is the whole grid's (the tests compare), in less time
    (``docs/tuning.md``). Last, where the uncapped profile's window widened, the narrow
    window with accelerations lowered locally (:func:`locally_capped`), if shorter.
    """
    if uncapped is None:
        uncapped = capped_profile(path, limits, 1.0)
    tried = {1.0: capped_motion(path, limits, second_share, 1.0, profile=uncapped)}
    peak = tried[1.0].peak
    higher, bisected = 1.0, False
    for share in (factor * peak for factor in FACTORS):
        x = capped_profile(path, limits, share)
        shortest_s = min(found.duration_s for found in tried.values())
        slower = profile_time(x, path.ds) > shortest_s
        if slower and (bisected or not tried[higher].widened):
            break
        if bisected and duration_lower_bound(path, limits, second_share, x) > shortest_s:
            continue  # cannot win, and past the bisection its widening is not asked
        tried[share] = capped_motion(path, limits, second_share, share, profile=x)
        if not bisected and tried[higher].widened and not tried[share].widened:
            bisect_widening(path, limits, second_share, tried, higher, share, peak)
            bisected = True
        if slower:  # its neighbour above widened: it was needed to tell whether the window stops
            break
        higher = share
    share = min(tried, key=lambda share: (tried[share].duration_s, -share))
    best = tried[share]
    for factor in RAMP_FACTORS:
        x = capped_profile(path, limits, share, factor * best.window_s)
        if duration_lower_bound(path, limits, second_share, x) > best.duration_s:
            continue
        found = capped_motion(path, limits, second_share, share, factor * best.window_s, profile=x)
        if found.duration_s < best.duration_s:
            best = found
    if tried[1.0].widened:
        local = locally_capped(path, limits, second_share, tried[1.0], best.duration_s, uncapped)
        if local.duration_s < best.duration_s:
            best = local
    return best


def locally_capped(
    path: ArcLengthPath,
    limits: FloatArray,
    second_share: float,
    uncapped: CappedMotion,
    shortest_s: float = np.inf,
    profile: FloatArray | None = None,
) -> CappedMotion:
    """The motion of :func:`~planning.curves.local_caps.locally_capped_motion` from the uncapped profile.

    ``uncapped``: the uncapped profile's motion, whose window widened; its narrower window is
    kept. Its duration is ``inf`` where no round is shorter than ``shortest_s`` [s].
    ``profile``: the uncapped profile itself, if the caller has it.
    """
    _, acceleration_cap = _caps(limits, 1.0, np.inf)
    step_s = time_step_s(limits)
    duration_s, motion = locally_capped_motion(
        path,
        limits,
        acceleration_cap,
        second_share,
        uncapped.window_s,
        step_s,
        TOLERANCE,
        shortest_s=shortest_s,
        uncapped=profile,
    )
    return CappedMotion(duration_s, False, uncapped.peak, uncapped.window_s, motion, step_s)


def bisect_widening(
    path: ArcLengthPath,
    limits: FloatArray,
    second_share: float,
    tried: dict[float, CappedMotion],
    high: float,
    low: float,
    peak: float,
) -> None:
    """Add to ``tried`` the largest cap in (``low``, ``high``) with no wider window, less :data:`MARGIN`.

    ``high``'s motion widened its window and ``low``'s did not; caps are shares of the limit.
    """
    bottom = low
    for _ in range(BISECTIONS):
        middle = 0.5 * (low + high)
        if capped_motion(path, limits, second_share, middle).widened:
            high = middle
        else:
            low = middle
    cap = low - MARGIN * peak
    if cap > bottom:
        x = capped_profile(path, limits, cap)
        if duration_lower_bound(path, limits, second_share, x) <= min(
            found.duration_s for found in tried.values()
        ):
            tried[cap] = capped_motion(path, limits, second_share, cap, profile=x)


def duration_lower_bound(
    path: ArcLengthPath, limits: FloatArray, second_share: float, x: FloatArray
) -> float:
    """A lower bound [s] of :func:`capped_motion`'s duration for the profile ``x``, without averaging.

    The averaged motion lasts the profile's time plus both windows, each at least the one the
    profile's accelerations need (:func:`_window_s`; a widening only adds), less the time
    grid's rounding (three steps); the final uniform scaling only stretches it.
    """
    window_s = jerk_window_s(path, x, limits[2])
    return profile_time(x, path.ds) + (1.0 + second_share) * window_s - 3.0 * time_step_s(limits)


def capped_profile(
    path: ArcLengthPath, limits: FloatArray, share: float, ramp_s: float = np.inf
) -> FloatArray:
    """Step 1: the phase-plane profile ``s'^2`` under the caps of :func:`_caps` and the torque rows."""
    velocity_cap, acceleration_cap = _caps(limits, share, ramp_s)
    d1, d2, v, a, offset = phase_plane_rows(path.dq, path.ddq, velocity_cap, acceleration_cap, path.torque)
    return phase_plane_profile(d1, d2, path.ds, v, a, offset)


def capped_motion(
    path: ArcLengthPath,
    limits: FloatArray,
    second_share: float,
    share: float,
    ramp_s: float = np.inf,
    profile: FloatArray | None = None,
) -> CappedMotion:
    """Steps 1 and 2 with the caps of :func:`_caps` (``profile``: step 1's, if already computed).

    ``second_share``: the second moving average's width as a share of the first's.
    Positions along the path are interpolated in its table at the profile's arc lengths.
    """
    x = capped_profile(path, limits, share, ramp_s) if profile is None else profile
    window = jerk_window_s(path, x, limits[2])
    peak = float(np.max(np.abs(path.dq) * np.sqrt(np.maximum(x, 0.0))[:, None] / limits[0]))
    step_s = time_step_s(limits)
    s = arc_at_times(x, path.ds, step_s)
    positions = positions_at(s, path.length, path.table)
    motion, used = jerk_limited_motion(positions, window, step_s, limits[2], ROUNDS, TOLERANCE, second_share)
    duration_s = scaled_duration(motion, step_s, *limits)
    return CappedMotion(duration_s, used > window, peak, window, motion, step_s)


def time_step_s(limits: FloatArray) -> float:
    """The time step [s] of the grid the joints' motion is averaged on: :data:`STEPS_PER_RAMP` a ramp."""
    return float(np.max(limits[1] / limits[2])) / STEPS_PER_RAMP


def _caps(limits: FloatArray, share: float, ramp_s: float) -> tuple[FloatArray, FloatArray]:
    """Velocity and acceleration caps of the profile.

    The velocity cap is ``share`` of the limit. The acceleration cap is the limit, or less
    where the jerk limit could not reach it before the velocity cap (``a = sqrt(v j)``, as in
    a jerk-limited profile that never holds its peak acceleration: a higher cap would only
    widen the moving average's window), or within ``ramp_s`` [s] (``a = j ramp_s``).
    """
    velocity_cap = share * limits[0]
    reachable = np.minimum(np.sqrt(velocity_cap * limits[2]), ramp_s * limits[2])
    return velocity_cap, np.minimum(limits[1], reachable)


def jerk_window_s(path: ArcLengthPath, x: FloatArray, jerk: FloatArray) -> float:
    """The moving average's width [s]: what the jerk limits need to ramp the profile's accelerations.

    Each joint's largest acceleration in the profile ``x`` (``q'' s'^2 + q' s''``) over its
    jerk limit; the widest of them.
    """
    push = path_acceleration(x, path.ds)[:-1]  # s'' on each grid interval
    acceleration = np.abs(path.ddq[:-1] * x[:-1, None] + path.dq[:-1] * push[:, None])
    return float(np.max(acceleration.max(axis=0) / jerk))
