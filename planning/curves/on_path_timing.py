"""Timing a path that must be followed exactly: the averages act on the arc length, not on each joint.

:func:`~planning.curves.path_timing.time_path` averages each joint's motion in time, which
keeps the limits but cuts the path's bends by a few millimetres: right for a free motion,
whose clearance is certified afterwards, wrong for a tool that must stay on a line. Here
the phase-plane profile's arc length ``s(t)`` is averaged instead, a single monotone
coordinate, and every sample of the motion is the path's own point at the averaged arc
length: ``q(t) = path(u(s_avg(t)))``. The motion never leaves the path; only the septic
between the trajectory's knots can, by the interpolation's error (``h^8``), which the caller
measures (:mod:`planning.task.line_deviation`).

As in :func:`~planning.curves.velocity_caps.fastest_motion`, the profile is also tried under
caps of its velocity (:data:`CAPS`), and the motion shortest once scaled to its limits is kept.
The averages bound the jerk of ``s``, not of each joint: a joint's jerk adds the path's
curvature terms (``3 q_ss s' s'' + q_sss s'^3``). The final uniform time scaling by the exact
extrema, as in :func:`~planning.curves.path_timing.time_path`, holds every joint to its
limits whatever they add. A straight path (whose curvature terms vanish) is timed the same
way by both functions, up to the rounding of the grids.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planning.curves.arc_length import FINE, ArcLengthPath, arc_length_path
from planning.curves.interpolating_spline import spline_through
from planning.curves.moving_average import arc_at_times, averaged_motion, scaled_duration
from planning.curves.path_pieces import split_at
from planning.curves.path_timing import (
    NODE_STEP_S,
    Smoothing,
    checked_limits,
    limits_time_scale,
    septic_through,
    smoothing_limits,
)
from planning.curves.torque_limits import TorqueModel, torque_rows
from planning.curves.trajectory import Trajectory
from planning.curves.velocity_caps import capped_profile, jerk_window_s, time_step_s

FloatArray = NDArray[np.float64]

CAPS = (0.9, 0.8, 0.7, 0.6, 0.5)
"""Caps of the phase-plane profile's velocity tried besides none, as shares of the limits.

A short motion switches from accelerating to braking at once, and a joint's jerk through that
switch, on a curved path its curvature terms too, makes the final scaling stretch the whole;
cruising a little below the peak is often faster (docs/tuning.md, "Tool lines"). The motion
of each cap is scaled to meet every limit at its samples, and the shortest is kept."""


def time_on_path(
    path: Trajectory,
    velocity: FloatArray,
    acceleration: FloatArray,
    jerk: FloatArray,
    node_step_s: float = NODE_STEP_S,
    torque: TorqueModel | None = None,
) -> Trajectory:
    """The C3 septic rest-to-rest trajectory along ``path`` whose every knot lies on it.

    Args:
        path: the geometric path ``q(u)``, at least C3 in ``u`` (a quintic spline, say); its
            start and end are the trajectory's.
        velocity: ``(nj,)`` limits [rad/s, m/s].
        acceleration: ``(nj,)`` limits [rad/s^2, m/s^2].
        jerk: ``(nj,)`` limits [rad/s^3, m/s^3].
        node_step_s: largest knot spacing [s]; smaller keeps the septic closer to the path
            between its knots.
        torque: the robot's torques and effort limits; ``None``: kinematic limits only.

    The velocity, acceleration and jerk are zero at both ends, so such motions join C3 at rest.

    Raises:
        PlanningError: the path does not move, or a limit is not finite and positive.
    """
    return _timed(path, (velocity, acceleration, jerk), node_step_s, torque).trajectory


@dataclass(frozen=True)
class MarkedMotion:
    """A motion along a path (:func:`time_on_path_marked`) and when it passes given points of it.

    Attributes:
        trajectory: the motion, with a knot at each of ``times`` too.
        times: ``(m,)`` when it passes the marks [s].
    """

    trajectory: Trajectory
    times: FloatArray


def time_on_path_marked(
    path: Trajectory,
    limits: tuple[FloatArray, FloatArray, FloatArray],
    marks: FloatArray,
    node_step_s: float = NODE_STEP_S,
    torque: TorqueModel | None = None,
) -> MarkedMotion:
    """:func:`time_on_path`'s motion (``limits``: velocity, acceleration, jerk), and when it passes ``marks``.

    ``marks`` ``(m,)``: values of the path's parameter strictly inside it. The time of each is
    found on the motion's own grid of arc lengths, and the trajectory is cut there exactly
    (:func:`~planning.curves.path_pieces.split_at`): its pieces between marks are the motion
    over each part of the path.
    """
    timed = _timed(path, limits, node_step_s, torque)
    times = np.interp(np.asarray(marks, dtype=float), timed.u, timed.grid_s) * timed.scale
    return MarkedMotion(split_at(timed.trajectory, times.tolist()), times)


@dataclass(frozen=True)
class _Timed:
    trajectory: Trajectory
    u: FloatArray  # the path parameter at each grid time, before the final scaling
    grid_s: FloatArray
    scale: float


def _timed(
    path: Trajectory,
    limits: tuple[FloatArray, FloatArray, FloatArray],
    node_step_s: float,
    torque: TorqueModel | None,
) -> _Timed:
    checked = checked_limits(path.n_joints, *limits)
    arc = arc_length_path(path, checked[0])
    smoothing = smoothing_limits(checked, node_step_s)
    if torque is not None:
        uncapped = capped_profile(arc, smoothing.limits, 1.0)
        arc = arc._replace(torque=torque_rows(path(arc.u), arc.dq, arc.ddq, arc.ds, torque, uncapped))
    step_s = time_step_s(smoothing.limits)
    parameter = path_parameter(path, arc.length)
    motions = [_capped(path, arc, parameter, smoothing, share, step_s) for share in (1.0, *CAPS)]
    durations = [scaled_duration(motion[0], step_s, *checked) for motion in motions]
    motion, u = motions[int(np.argmin(durations))]
    ends = path(path.knots[[0, -1]])
    trajectory = septic_through(motion, step_s, smoothing.step_s, ends, still=4)
    scale = limits_time_scale(trajectory, checked, torque)
    return _Timed(trajectory.time_scaled(scale), u, np.arange(len(u), dtype=float) * step_s, scale)


def _capped(
    path: Trajectory,
    arc: ArcLengthPath,
    parameter: Trajectory,
    smoothing: Smoothing,
    share: float,
    step_s: float,
) -> tuple[FloatArray, FloatArray]:
    """``(4, T, nj)`` the motion on the path under a velocity cap of ``share`` of the limits, and ``u``."""
    profile = capped_profile(arc, smoothing.limits, share)
    window_s = jerk_window_s(arc, profile, smoothing.limits[2])
    s = arc_at_times(profile, arc.ds, step_s)
    averaged = averaged_motion(s[:, None], window_s, step_s, smoothing.second_share)[0, :, 0]
    u = parameter(np.clip(averaged, 0.0, arc.length[-1]))[:, 0]
    return _derivatives(path(u), step_s), np.asarray(u)


def path_parameter(path: Trajectory, length: FloatArray) -> Trajectory:
    """``u(s)``: the path's own parameter at an arc length, a smooth (C4) interpolant.

    ``length`` ``(FINE,)``: the arc length at :data:`~planning.curves.arc_length.FINE` samples
    uniform in ``u`` (:func:`~planning.curves.arc_length.arc_length_path`). Linear
    interpolation would put a kink at every sample, which the motion's third differences turn
    into jerk; samples where the path stands still (repeated lengths) are passed once.
    """
    u = np.linspace(path.knots[0], path.knots[-1], FINE)
    rising = np.concatenate([[True], np.diff(length) > 0.0])
    return spline_through(length[rising], u[rising, None])


def _derivatives(positions: FloatArray, step_s: float) -> FloatArray:
    """``(4, T, nj)`` positions and their first three derivatives by central differences.

    Differences of the positions themselves, as :func:`~planning.curves.moving_average.averaged_motion`
    takes them: the Hermite data of a septic must agree with each other.
    """
    out = np.empty((4, *positions.shape))
    out[0] = positions
    for r in range(1, 4):
        out[r] = np.gradient(out[r - 1], step_s, axis=0)
    return out
