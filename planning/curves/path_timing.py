"""Timing a geometric path as fast as velocity, acceleration and jerk limits allow, as a C3 septic.

Given a path ``q(u)``, :func:`time_path` returns a rest-to-rest
:class:`~planning.curves.trajectory.Trajectory` along it: septic segments, continuous in
position, velocity, acceleration and jerk, within every limit by its exact extrema, and
touching one of them (no time left on the table). Steps:

1. **Velocity and acceleration.** The fastest speed along the path under both limits, by the
   phase-plane method (:mod:`planning.curves.phase_plane`) in the path's arc length
   (:mod:`planning.curves.arc_length`, each joint scaled by its velocity limit): regular
   even where the path's own parameter slows to a stop, as the planner's rest-to-rest
   splines do at their ends.
2. **Jerk.** Each joint's motion goes through two moving averages of widths ``w = max_j
   a_j / j_j`` and ``r w`` (``r`` at least 1/8, :func:`smoothing_limits`; the "FIR"
   interpolation of CNC controllers, Tajima and Sencer 2016). An average of velocities
   within their limit stays within it, and so does one of accelerations; the jerk is the
   change of acceleration over a window, at most ``a / w = j`` where the profile ramps its
   acceleration up or down, as Ruckig's time-optimal solution also takes ``a / j`` to. Where
   it switches from accelerating to braking at once (a short move), the window widens until
   the jerk fits. The motion ends ``(1 + r) w`` later; the averaged path cuts bends by a few
   millimetres (the averages of nearby points of a curve lie inside it), which the planner's
   certified check accounts for. Steps 1 and 2 are tried under several caps of the profile's
   velocity and acceleration, and, where the window would widen, with the narrow window and
   the swinging joint's acceleration lowered only where its jerk exceeds
   (:mod:`planning.curves.local_caps`); the fastest motion is kept
   (:mod:`planning.curves.velocity_caps`).
3. **Septic.** Knots every ``node_step_s``; the averaged position, velocity, acceleration and
   jerk there are the Hermite data of the segments (paper eq. 14), so the trajectory is C3
   by construction.
4. **Exactness.** A uniform time scaling by the exact extrema of the polynomials makes the
   largest ``|derivative| / limit`` exactly one.

Why not uniform scaling alone (what the planner did before): a polynomial shape's velocity
is a bell whose peak is about twice its mean, so most of the motion runs far below the
limits. How close this method comes to Ruckig's time-optimal jerk-limited duration:
``docs/benchmarks.md`` (``scripts/bench_timing.py``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from planning.curves.arc_length import arc_length_path
from planning.curves.hermite import HERMITE_INV, node_scaling
from planning.curves.torque_limits import TorqueModel, torque_rows, torque_time_scale
from planning.curves.trajectory import Trajectory
from planning.curves.velocity_caps import capped_profile, fastest_motion
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]

NODE_STEP_S = 0.1
"""Largest spacing of the trajectory's knots [s]."""
MIN_NODE_STEP_S = 0.02
"""Smallest spacing of the trajectory's knots [s] (see :func:`smoothing_limits`)."""
SECOND_SHARE = 0.125
"""The second moving average's least width, as a share of the first's (:func:`smoothing_limits`)."""
SEPTIC_JERK_AIM = 1.025
"""How far below a binding jerk limit the averages aim (its divisor, :func:`smoothing_limits`).

The septic through the averaged motion's knots overshoots the motion's jerk between them
(2.7 % at the median on 300 paths of the CPR, ``docs/tuning.md``), and step 4 would stretch
the whole motion by the cube root of that; aiming lower widens only the acceleration ramps."""


def time_path(
    path: Trajectory,
    velocity: FloatArray,
    acceleration: FloatArray,
    jerk: FloatArray,
    node_step_s: float = NODE_STEP_S,
    torque: TorqueModel | None = None,
    still_jerk: bool = False,
) -> Trajectory:
    """The fast C3 septic rest-to-rest trajectory along ``path`` of the steps above.

    With a ``torque`` model the joint torques stay within its effort limits too: as rows of
    the phase plane in step 1 (:func:`~planning.curves.torque_limits.torque_rows`), and in
    the uniform scaling of step 4 (:func:`~planning.curves.torque_limits.torque_time_scale`).

    Args:
        path: the geometric path; its start and end are the trajectory's.
        velocity: ``(nj,)`` limits [rad/s, m/s].
        acceleration: ``(nj,)`` limits [rad/s^2, m/s^2].
        jerk: ``(nj,)`` limits [rad/s^3, m/s^3].
        node_step_s: largest knot spacing [s] (:func:`smoothing_limits`).
        torque: the robot's torques and effort limits; ``None``: kinematic limits only.
        still_jerk: the jerk is zero at both ends too (not only the velocity and the
            acceleration), so that such trajectories join C3 at rest
            (:mod:`planning.curves.stop_and_go`).

    Raises:
        PlanningError: the path does not move, or a limit is not finite and positive.
    """
    limits = checked_limits(path.n_joints, velocity, acceleration, jerk)
    arc = arc_length_path(path, limits[0])
    smoothing = smoothing_limits(limits, node_step_s)
    uncapped = None
    if torque is not None:
        uncapped = capped_profile(arc, smoothing.limits, 1.0)
        arc = arc._replace(torque=torque_rows(path(arc.u), arc.dq, arc.ddq, arc.ds, torque, uncapped))
        uncapped = uncapped if arc.torque is None else None  # the rows change it
    fastest = fastest_motion(arc, smoothing.limits, smoothing.second_share, uncapped)
    ends = path(path.knots[[0, -1]])
    trajectory = septic_through(
        fastest.motion, fastest.step_s, smoothing.step_s, ends, 4 if still_jerk else 3
    )
    return trajectory.time_scaled(limits_time_scale(trajectory, limits, torque))


def checked_limits(
    n_joints: int, velocity: FloatArray, acceleration: FloatArray, jerk: FloatArray
) -> FloatArray:
    """``(3, nj)`` velocity, acceleration and jerk limits, each ``n_joints`` finite values > 0.

    Raises:
        PlanningError: a shape other than ``(n_joints,)``, or a value not finite and positive.
    """
    given = [np.asarray(x, dtype=float) for x in (velocity, acceleration, jerk)]
    shapes = [x.shape for x in given]
    if any(shape != (n_joints,) for shape in shapes):
        raise PlanningError(
            f"velocity, acceleration and jerk limits of shapes {shapes}; {n_joints} values each, "
            "one per joint of the path"
        )
    limits = np.stack(given)
    if not np.all(np.isfinite(limits) & (limits > 0)):
        raise PlanningError(f"limits {limits.tolist()} must be finite and > 0 for {n_joints} joints")
    return limits


class Smoothing(NamedTuple):
    """How a robot's limits are smoothed in steps 1 and 2 (:func:`smoothing_limits`)."""

    step_s: float
    """The trajectory's knot spacing [s]."""
    limits: FloatArray
    """``(3, nj)`` velocity, acceleration and jerk limits of the phase plane and the averages."""
    second_share: float
    """The second moving average's width as a share of the first."""


def smoothing_limits(limits: FloatArray, node_step_s: float) -> Smoothing:
    """The knot spacing, the limits of steps 1 and 2, and the second average's share for ``limits``.

    A septic segment cannot follow an acceleration that ramps up much faster than the
    segment lasts: between its knots it overshoots, and the final scaling pays for it (a
    Panda, whose jerk limits ramp its accelerations in 2 ms, ran 25 % slower through knots
    every 0.1 s). So the knots come every quarter ramp ``w = max_j a_j / j_j`` (between
    :data:`MIN_NODE_STEP_S` and ``node_step_s``), and the moving average ramps no faster
    than two knot spacings: its jerk limits are lowered to ``a / (2 step)`` where they are
    higher. The second average, which rounds the jerk's steps so that the septic does not
    overshoot them, spans half a knot spacing, and at least :data:`SECOND_SHARE` of the
    ramp: the motion lasts that much longer than the first average's (``docs/method.md``).
    Where the jerk limit itself binds (ramps of at least two spacings: the CPR's), the
    averages aim at :data:`SEPTIC_JERK_AIM` below it, the septic's overshoot between its
    knots. The final scaling still holds the trajectory to the given limits.
    """
    step = float(np.clip(np.max(limits[1] / limits[2]) / 4.0, MIN_NODE_STEP_S, node_step_s))
    jerk = np.minimum(limits[2] / SEPTIC_JERK_AIM, limits[1] / (2.0 * step))
    aimed = np.stack([limits[0], limits[1], jerk])
    ramp_s = float(np.max(aimed[1] / aimed[2]))
    return Smoothing(step, aimed, max(SECOND_SHARE, step / (2.0 * ramp_s)))


def limits_time_scale(trajectory: Trajectory, limits: FloatArray, torque: TorqueModel | None = None) -> float:
    """The uniform time scale at which ``trajectory`` meets its first limit exactly.

    ``limits`` ``(3, nj)``: velocity, acceleration and jerk limits (exact extrema); with a
    ``torque`` model also its effort limits (:func:`~planning.curves.torque_limits.torque_time_scale`;
    ignored where gravity alone exceeds them: the verification names that torque).
    """
    scale = trajectory.time_scale_for_limits(*limits)
    if torque is None:
        return scale
    torque_scale = torque_time_scale(trajectory, torque, at_least=scale)
    return max(scale, torque_scale) if np.isfinite(torque_scale) else scale


def septic_through(
    motion: FloatArray, step_s: float, node_step_s: float, ends: FloatArray, still: int = 3
) -> Trajectory:
    """Septic Hermite segments whose knots take the motion's position and derivatives.

    ``motion`` ``(4, T, nj)`` holds them every ``step_s`` [s].
    The first and last knots are exactly ``ends`` ``(2, nj)``, at rest: their derivatives
    of orders 1 to ``still - 1`` are zero.
    """
    samples = len(motion[0])
    count = max(1, int(np.ceil((samples - 1) * step_s / node_step_s)))
    index = np.round(np.linspace(0, samples - 1, count + 1)).astype(int)
    knots = index * step_s
    data = motion[:, index].transpose(1, 2, 0)  # (knots, nj, 4)
    data[[0, -1], :, 0] = ends
    data[[0, -1], :, 1:still] = 0.0
    steps = np.diff(knots)
    hermite = np.concatenate([data[:-1], data[1:]], axis=2) * node_scaling(steps)[:, None, :]
    start = data[:-1, :, 0].copy()  # each segment solved about its first position: the jerk's
    hermite[:, :, [0, 4]] -= start[:, :, None]  # rounding then scales with the segment's motion
    coefficients = (hermite @ HERMITE_INV.T) * (steps[:, None, None] ** -np.arange(8.0))
    coefficients[:, :, 0] += start
    return Trajectory(knots=knots, coefficients=coefficients)
