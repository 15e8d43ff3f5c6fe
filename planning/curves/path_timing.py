"""Timing a geometric path as fast as velocity, acceleration and jerk limits allow, as a C3 septic.

Given a path ``q(u)``, :func:`time_path` returns a rest-to-rest
:class:`~planning.curves.trajectory.Trajectory` along it: septic segments, continuous in
position, velocity, acceleration and jerk, within every limit by its exact extrema, and
touching one of them (no time left on the table). Steps:

1. **Velocity and acceleration.** The fastest speed along the path under both limits, by the
   phase-plane method (:mod:`planning.curves.phase_plane`) in the path's arc length (each
   joint scaled by its velocity limit): regular even where the path's own parameter slows
   to a stop, as the planner's rest-to-rest splines do at their ends.
2. **Jerk.** Each joint's motion goes through two moving averages of widths ``w = max_j
   a_j / j_j`` and ``w / 4`` (the "FIR" interpolation of CNC controllers, Tajima and Sencer
   2016). An average of velocities within their limit stays within it, and so does one of
   accelerations; the jerk is the change of acceleration over a window, at most ``a / w = j``
   where the profile ramps its acceleration up or down, as Ruckig's time-optimal solution
   also takes ``a / j`` to. Where it switches from accelerating to braking at once (a short
   move), the window widens until the jerk fits. The motion ends ``1.25 w`` later; the
   averaged path cuts bends by a few millimetres (the averages of nearby points of a curve
   lie inside it), which the planner's certified check accounts for.
3. **Septic.** Knots every ``node_step_s``; the averaged position, velocity, acceleration and
   jerk there are the Hermite data of the segments (paper eq. 14), so the trajectory is C3
   by construction.
4. **Exactness.** A uniform time scaling by the exact extrema of the polynomials makes the
   largest ``|derivative| / limit`` exactly one.

Why not uniform scaling alone (what the planner did before): a polynomial shape's velocity
is a bell whose peak is about twice its mean, so most of the motion runs far below the
limits (2.3x Ruckig's free-space bound on generated scenes). On a straight line this method
comes within a few percent of Ruckig's time-optimal jerk-limited duration.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planning.curves.hermite import HERMITE_INV, node_scaling
from planning.curves.phase_plane import phase_plane_profile
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]

GRID = 512
"""Grid points of the phase-plane profile along the path (uniform in its parameter)."""
FINE = 2049
"""Samples of the path's parameter from which its arc length is integrated."""
TIME_STEP_S = 1e-3
"""Step of the time grid on which the joints' motion is averaged [s]."""
NODE_STEP_S = 0.1
"""Spacing of the trajectory's knots [s]."""
ROUNDS = 3
"""Most widenings of the averaging window for a jerk beyond the limit."""
TOLERANCE = 0.02
"""Excess of a limit left to the final uniform scaling."""
ACCELERATION_SHARES = (1.0, 0.7, 0.5)
"""Shares of the acceleration limit tried for the phase-plane profile. A short move switches
from accelerating to braking at once, and the jerk of that switch is cheaper to meet with a
gentler acceleration than with a wider average; the fastest result is kept."""


def jerk_allowance_s(acceleration: FloatArray, jerk: FloatArray) -> float:
    """What the moving averages add to the phase-plane time [s]: ``1.25 max_j a_j / j_j``."""
    return 1.25 * float(np.max(np.asarray(acceleration) / np.asarray(jerk)))


def _arc_length_grid(
    path: Trajectory, velocity: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, tuple[FloatArray, FloatArray]]:
    """The path in its arc length ``s``, on a grid uniform in its own parameter ``u``.

    Returns ``dq/ds`` and ``d2q/ds2`` at the grid points, the steps ``ds`` between them, and
    the fine table ``(s, u)`` from which positions along the path are interpolated. ``s``
    measures each joint in seconds at its velocity limit. A grid uniform in ``u`` is dense in
    ``s`` where the path is slow in ``u``: at its ends and where it turns sharply, which is
    where the phase plane needs resolution. The derivatives follow from the chain rule
    exactly (``q' / s'`` and ``(q'' - dq/ds s'') / s'^2``); where ``q'`` vanishes they take
    their neighbours' values.
    """
    fine = np.linspace(path.knots[0], path.knots[-1], FINE)
    rate = np.linalg.norm(path(fine, 1) / velocity, axis=1)
    length = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(fine))])
    if not length[-1] > 0:
        raise PlanningError("the path does not move: there is nothing to time")
    pick = np.linspace(0, FINE - 1, GRID).round().astype(int)
    u, s = fine[pick], length[pick]
    d1, d2 = path(u, 1), path(u, 2)
    speed = rate[pick]
    moving = speed > 1e-9 * speed.max()
    dq = np.zeros_like(d1)
    ddq = np.zeros_like(d2)
    dq[moving] = d1[moving] / speed[moving, None]
    bend = np.sum(d1[moving] * d2[moving] / velocity**2, axis=1) / speed[moving]  # s''(u)
    ddq[moving] = (d2[moving] - dq[moving] * bend[:, None]) / speed[moving, None] ** 2
    for index in np.flatnonzero(~moving):  # take the nearest moving neighbour's values
        nearest = np.flatnonzero(moving)[np.argmin(np.abs(np.flatnonzero(moving) - index))]
        dq[index], ddq[index] = dq[nearest], ddq[nearest]
    steps = np.diff(s)
    keep = np.concatenate([[True], steps > 0])  # drop repeated points (the path standing still)
    return dq[keep], ddq[keep], np.diff(s[keep]), (length, fine)


def _timed_positions(
    path: Trajectory, table: tuple[FloatArray, FloatArray], ds: FloatArray, x: FloatArray
) -> FloatArray:
    """Positions ``(T, nj)`` every ``TIME_STEP_S`` along the profile ``x`` on the grid of steps ``ds``.

    Between grid points the path acceleration ``s''`` is constant, so ``s(t)`` is exact there.
    """
    speed = np.sqrt(np.maximum(x, 0.0))
    push = np.diff(x) / (2.0 * ds)  # s'' on each grid interval
    steps = 2.0 * ds / np.maximum(speed[:-1] + speed[1:], 1e-12)
    knot_times = np.concatenate([[0.0], np.cumsum(steps)])
    grid = np.concatenate([[0.0], np.cumsum(ds)])
    times = np.append(np.arange(0.0, knot_times[-1], TIME_STEP_S), knot_times[-1])
    g = np.clip(np.searchsorted(knot_times, times, side="right") - 1, 0, len(x) - 2)
    tau = times - knot_times[g]
    s = np.minimum(grid[g] + speed[g] * tau + 0.5 * push[g] * tau**2, grid[-1])
    # u(s) from the fine table: its kinks (where the interpolation's slope changes) are small
    return path(np.interp(s, *table))


def _average(values: FloatArray, width: int) -> FloatArray:
    """Causal moving average over ``width`` samples along axis 0, ``width`` samples longer.

    Before and after the motion the robot stands at its first and last position.
    """
    before = np.repeat(values[:1], width, axis=0)
    after = np.repeat(values[-1:], width - 1, axis=0)
    total = np.cumsum(np.concatenate([np.zeros((1, values.shape[1])), before, values, after]), axis=0)
    return np.asarray((total[width:] - total[:-width]) / width)


def _filtered(positions: FloatArray, window_s: float) -> list[FloatArray]:
    """Position, velocity, acceleration and jerk of the positions averaged over ``window_s``, then a quarter.

    The derivatives are those of the averaged positions themselves (central differences of a
    smooth signal): the Hermite data of the septic must agree with each other, or the small
    disagreements become large jerks over a short segment.
    """
    widths = (max(1, round(window_s / TIME_STEP_S)), max(1, round(window_s / 4 / TIME_STEP_S)))
    for width in widths:
        positions = _average(positions, width)
    out = [positions]
    for _ in range(3):
        out.append(np.gradient(out[-1], TIME_STEP_S, axis=0))
    return out


def time_path(
    path: Trajectory,
    velocity: FloatArray,
    acceleration: FloatArray,
    jerk: FloatArray,
    node_step_s: float = NODE_STEP_S,
) -> Trajectory:
    """The fast C3 septic rest-to-rest trajectory along ``path`` of the steps above.

    Args:
        path: the geometric path; its start and end are the trajectory's.
        velocity: ``(nj,)`` limits [rad/s, m/s].
        acceleration: ``(nj,)`` limits [rad/s^2, m/s^2].
        jerk: ``(nj,)`` limits [rad/s^3, m/s^3].
        node_step_s: knot spacing [s].

    Raises:
        PlanningError: the path does not move, or a limit is not finite and positive.
    """
    limits = np.stack([np.asarray(x, dtype=float) for x in (velocity, acceleration, jerk)])
    if limits.shape != (3, path.n_joints) or not np.all(np.isfinite(limits) & (limits > 0)):
        raise PlanningError(
            f"limits of shape {limits.shape} must be finite and > 0 for {path.n_joints} joints"
        )
    dq, ddq, ds, table = _arc_length_grid(path, limits[0])
    best: list[FloatArray] = []
    best_time = np.inf
    for share in ACCELERATION_SHARES:
        x = phase_plane_profile(dq, ddq, ds, limits[0], share * limits[1])
        positions = _timed_positions(path, table, ds, x)
        window = share * float(np.max(limits[1] / limits[2]))
        for _ in range(ROUNDS + 1):
            motion = _filtered(positions, window)
            usage = float(np.max(np.abs(motion[3]) / limits[2]))
            if usage <= 1.0 + TOLERANCE:
                break
            window *= min(usage, 2.0)  # the profile switches faster than a / j: ramp it slower
        # its duration once a uniform scaling meets every limit, to compare the shares fairly
        usages = [float(np.max(np.abs(motion[r]) / limits[r - 1])) ** (1.0 / r) for r in (1, 2, 3)]
        duration = len(motion[0]) * TIME_STEP_S * max(*usages, 1.0)
        if duration < best_time:
            best, best_time = motion, duration
    trajectory = _septic(best, node_step_s, path(path.knots[[0, -1]]))
    return trajectory.time_scaled(trajectory.time_scale_for_limits(*limits))


def _septic(motion: list[FloatArray], node_step_s: float, ends: FloatArray) -> Trajectory:
    """Septic Hermite segments whose knots take the motion's position and derivatives.

    The first and last knots are exactly ``ends`` ``(2, nj)``, at rest.
    """
    samples = len(motion[0])
    count = max(1, int(np.ceil((samples - 1) * TIME_STEP_S / node_step_s)))
    index = np.round(np.linspace(0, samples - 1, count + 1)).astype(int)
    knots = index * TIME_STEP_S
    data = np.stack([values[index] for values in motion], axis=2)  # (knots, nj, 4)
    data[[0, -1], :, 0] = ends
    data[[0, -1], :, 1:3] = 0.0
    steps = np.diff(knots)
    hermite = np.concatenate([data[:-1], data[1:]], axis=2) * node_scaling(steps)[:, None, :]
    coefficients = (hermite @ HERMITE_INV.T) * (steps[:, None, None] ** -np.arange(8.0))
    return Trajectory(knots=knots, coefficients=coefficients)
