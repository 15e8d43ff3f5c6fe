"""How far a timed motion leaves its tool line, certified at every instant, not only at samples.

The deviation at an instant: the distance of the tool frame's origin from the segment, and
the angle between the tool frame's orientation and the line's at the same progress ``sigma``
(the origin's projection on the segment; for a line that only turns, the orientation's
projection on its turn). Both are measured by forward kinematics at samples ``dt`` apart,
and bounded between them by how fast they can change: the tool's origin moves at most
``sum_j L_j |q'_j|`` (each joint's lever to the tool frame, 1 for a prismatic one:
:func:`cpr_kin.kinematics.forward.frame_levers`), its orientation turns at most
``sum_j |q'_j|`` over the revolute joints of its chain, with each joint's speed bounded over
the interval by the trajectory's own
(:meth:`~planning.curves.trajectory.Trajectory.speed_bounds`). A distance that changes at
most at rate ``V`` and is ``d_k``, ``d_k+1`` at the interval's ends stays below
``(d_k + d_k+1 + V dt) / 2``: the certified bound. ``dt`` is chosen so that ``V dt`` is
:data:`SLACK_SHARE` of the tolerance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.kinematics.forward import frame_levers
from planning.curves.trajectory import Trajectory
from planning.task.limits import SHORTEST_LINE_M
from planning.task.tool_line import LineGeometry, LineTolerance

FloatArray = NDArray[np.float64]

SLACK_SHARE = 0.5
"""The largest change of the deviation between two samples, as a share of the tolerance: the
certified bound is at most the samples' deviation plus half of it."""
LONGEST_STEP_S = 1e-3
"""The samples' spacing at most [s] (every millisecond, as a robot controller sees the motion)."""
MOST_SAMPLES = 400_000
"""Most samples of one check (a 40 s line at 0.1 ms)."""


@dataclass(frozen=True)
class LineDeviation:
    """The deviation of a timed motion from its line (:func:`line_deviation`).

    Attributes:
        position_m: certified bound of the tool's distance from the segment, at every instant [m].
        angle_rad: certified bound of its rotation from the line's orientation [rad].
        sampled_position_m: the largest distance at the samples [m].
        sampled_angle_rad: the largest rotation at the samples [rad].
        worst_time_s: when the sampled distance, over its tolerance, or the angle is largest [s].
        step_s: the samples' spacing [s].
        tool_speed_m_s: the tool origin's largest speed between two samples [m/s].
    """

    position_m: float
    angle_rad: float
    sampled_position_m: float
    sampled_angle_rad: float
    worst_time_s: float
    step_s: float
    tool_speed_m_s: float

    def within(self, tolerance: LineTolerance) -> bool:
        """Both certified bounds are within ``tolerance``."""
        return self.position_m <= tolerance.position_m and self.angle_rad <= tolerance.angle_rad


def line_deviation(
    robot: ck.Robot, frame: str, geometry: LineGeometry, trajectory: Trajectory, tolerance: LineTolerance
) -> LineDeviation:
    """The certified deviation of ``trajectory`` from ``geometry`` (the module's rule)."""
    levers = frame_levers(robot, frame)
    lever, turns = levers.levers, levers.turns
    peak = trajectory.extrema(1).peak
    shift = float(np.linalg.norm(geometry.shift_m))
    turn = float(np.linalg.norm(geometry.turn))
    # how fast the angle can change: the tool turning, and the line's orientation at its progress
    follow = turn / shift if shift >= SHORTEST_LINE_M else 0.0
    # for a line that only turns, the rotation's projection moves at most pi/2 times as fast as the tool turns
    rotate_rate = 1.0 if follow else 1.0 + math.pi / 2
    speed, spin = float(peak @ lever), float(peak @ turns)
    step_s = min(
        LONGEST_STEP_S,
        SLACK_SHARE * tolerance.position_m / max(speed, 1e-12),
        SLACK_SHARE * tolerance.angle_rad / max(rotate_rate * spin + follow * speed, 1e-12),
    )
    t0, t1 = float(trajectory.knots[0]), float(trajectory.knots[-1])
    count = min(MOST_SAMPLES, math.ceil((t1 - t0) / step_s) + 1)
    times = np.linspace(t0, t1, count)
    poses = ck.frame_poses(robot, trajectory(times), frame)
    distance, angle = _deviations(geometry, poses)
    bounds = trajectory.speed_bounds(times)
    dt = np.diff(times)
    v, w = bounds @ lever, bounds @ turns
    worst = int(np.argmax(np.maximum(distance / tolerance.position_m, angle / tolerance.angle_rad)))
    moved = np.linalg.norm(np.diff(poses[:, :3, 3], axis=0), axis=1)
    return LineDeviation(
        position_m=float(np.max(0.5 * (distance[:-1] + distance[1:] + v * dt))),
        angle_rad=float(np.max(0.5 * (angle[:-1] + angle[1:] + (rotate_rate * w + follow * v) * dt))),
        sampled_position_m=float(distance.max()),
        sampled_angle_rad=float(angle.max()),
        worst_time_s=float(times[worst]),
        step_s=float(dt.max()),
        tool_speed_m_s=float(np.max(moved / dt)),
    )


def _deviations(geometry: LineGeometry, poses: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(N,)`` distances [m] and angles [rad] of the tool placements ``poses`` ``(N, 4, 4)``."""
    positions, rotations = poses[:, :3, 3], poses[:, :3, :3]
    sigma = geometry.progress(positions, rotations)
    on_line = geometry.start.translation + sigma[:, None] * geometry.shift_m
    distance = np.linalg.norm(positions - on_line, axis=1)
    references = geometry.rotations(sigma)
    relative = np.einsum("nji,njk->nik", references, rotations)
    return distance, rotation_angles(relative)


def rotation_angles(rotations: FloatArray) -> FloatArray:
    """``(N,)`` the angles [rad] of rotation matrices ``(N, 3, 3)``, accurate near zero too.

    ``atan2(|axis| sin, cos)`` from the skew and symmetric parts: ``arccos`` of the trace loses
    half the digits near the identity.
    """
    skew = rotations - np.swapaxes(rotations, 1, 2)
    sine = 0.5 * np.linalg.norm(np.stack([skew[:, 2, 1], skew[:, 0, 2], skew[:, 1, 0]], axis=1), axis=1)
    cosine = 0.5 * (np.trace(rotations, axis1=1, axis2=2) - 1.0)
    return np.asarray(np.arctan2(sine, cosine))
