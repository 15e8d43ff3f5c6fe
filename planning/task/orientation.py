"""An orientation constraint on a free motion (the upright glass), its deviation certified at every instant.

:class:`OrientationConstraint` holds the tool frame's orientation about some of its own axes
within an angle of a reference orientation, the others free:

- all three axes held: the angle of the rotation from the reference (the geodesic angle);
- two held (``[x, y]``: roll and pitch of an upright carry, yaw free): the angle between the
  free axis (``z``) and the reference's; turning about it costs nothing.

Both angles change at most as fast as the tool turns: over the revolute joints of its chain,
``sum_j |q'_j|`` bounds that, with each joint's speed bounded over an interval by the
trajectory's own (:meth:`~planning.curves.trajectory.Trajectory.speed_bounds`).
:func:`orientation_deviation` measures the angle by forward kinematics at samples at most
1 ms apart, and between two samples bounds it by ``(a_k + a_k+1 + W dt) / 2`` (as a tool
line's deviation, :mod:`planning.task.line_deviation`).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.kinematics.forward import frame_levers
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.task.limits import COARSEST_ANGLE_RAD, FINEST_ANGLE_RAD, UPRIGHT_RAD
from planning.task.line_deviation import LONGEST_STEP_S, MOST_SAMPLES, SLACK_SHARE, rotation_angles
from planning.task.tool_line import ToolPose
from planning.validation import number_in

FloatArray = NDArray[np.float64]

AXES = ("x", "y", "z")
"""The tool frame's axes, by name."""


@dataclass(frozen=True)
class OrientationConstraint:
    """Keep the tool frame's orientation within ``angle_rad`` of a reference about ``axes``.

    Attributes:
        axes: the frame's axes held, two or three of ``x``, ``y``, ``z`` (``("x", "y")``: the
            frame's ``z`` axis keeps its direction, turning about it is free).
        angle_rad: the largest angle from the reference [rad] (module docstring).
        quat_xyzw: the reference orientation in the base frame, a unit quaternion
            ``(x, y, z, w)``; ``None``: the frame's at the motion's start.
        frame: the constrained frame; ``None``: the robot's tool frame.
    """

    axes: tuple[str, ...] = ("x", "y")
    angle_rad: float = UPRIGHT_RAD
    quat_xyzw: tuple[float, float, float, float] | None = None
    frame: str | None = None

    def __post_init__(self) -> None:
        axes = tuple(self.axes)
        if len(axes) not in (2, 3) or len(set(axes)) != len(axes) or not set(axes) <= set(AXES):
            raise PlanningError(
                f"constraint axes = {list(axes)}; give two or three different axes of {list(AXES)} "
                "(['x', 'y']: an upright carry, turning about z free; all three: the whole orientation)"
            )
        object.__setattr__(self, "axes", tuple(sorted(axes)))
        number_in("constraint angle_rad", self.angle_rad, FINEST_ANGLE_RAD, COARSEST_ANGLE_RAD, "rad")
        if self.quat_xyzw is not None:
            quat = ToolPose((0.0, 0.0, 0.0), self.quat_xyzw).quat_xyzw  # checked and normalised
            object.__setattr__(self, "quat_xyzw", quat)

    def about(self, rotation: FloatArray) -> OrientationConstraint:
        """The constraint about ``rotation`` ``(3, 3)`` where it names no reference (a start's)."""
        if self.quat_xyzw is not None:
            return self
        quat = ToolPose.of(pin.SE3(np.asarray(rotation), np.zeros(3))).quat_xyzw
        return dataclasses.replace(self, quat_xyzw=quat)

    def reference(self) -> FloatArray:
        """``(3, 3)`` the reference orientation (:attr:`quat_xyzw`, which must be given)."""
        if self.quat_xyzw is None:
            raise PlanningError("the constraint's reference orientation is not set (quat_xyzw)")
        return np.asarray(ToolPose((0.0, 0.0, 0.0), self.quat_xyzw).placement().rotation)

    @cached_property
    def free_axis(self) -> int | None:
        """The index of the free axis (0, 1, 2 for x, y, z), ``None`` when all three are held."""
        free = [i for i, name in enumerate(AXES) if name not in self.axes]
        return free[0] if free else None

    def angles(self, rotations: FloatArray, reference: FloatArray) -> FloatArray:
        """``(N,)`` the constraint's angle [rad] of frame orientations ``(N, 3, 3)`` from ``reference``."""
        free = self.free_axis
        if free is None:
            return rotation_angles(np.einsum("ji,njk->nik", reference, rotations))
        axis, wanted = rotations[:, :, free], reference[:, free]
        sine = np.linalg.norm(np.cross(axis, wanted), axis=1)
        return np.asarray(np.arctan2(sine, axis @ wanted))

    def error(self, rotation: FloatArray, reference: FloatArray) -> FloatArray:
        """``(3,)`` the least world-aligned rotation [rad] that brings ``rotation`` onto the constraint.

        Its norm is :meth:`angles`; a rotation about the free axis is not part of it.
        """
        free = self.free_axis
        if free is None:
            return np.asarray(rotation @ pin.log3(rotation.T @ reference))
        (a0, a1, a2), (b0, b1, b2) = rotation[:, free].tolist(), reference[:, free].tolist()
        normal = (a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0)  # a cross product, in floats
        sine = math.sqrt(normal[0] ** 2 + normal[1] ** 2 + normal[2] ** 2)
        if sine < 1e-15:
            return np.zeros(3)
        scale = math.atan2(sine, a0 * b0 + a1 * b1 + a2 * b2) / sine
        return np.array([normal[0] * scale, normal[1] * scale, normal[2] * scale])


@dataclass(frozen=True)
class OrientationDeviation:
    """How far a timed motion leaves its orientation constraint (:func:`orientation_deviation`).

    Attributes:
        angle_rad: certified bound of the constraint's angle at every instant [rad].
        sampled_angle_rad: the largest angle at the samples [rad].
        worst_time_s: when the sampled angle is largest [s].
        step_s: the samples' spacing [s].
    """

    angle_rad: float
    sampled_angle_rad: float
    worst_time_s: float
    step_s: float


def orientation_deviation(
    robot: ck.Robot,
    frame: str,
    constraint: OrientationConstraint,
    reference: FloatArray,
    trajectory: Trajectory,
) -> OrientationDeviation:
    """The certified angle of ``trajectory`` from ``constraint`` about ``reference`` (the module's rule)."""
    turns = frame_levers(robot, frame).turns
    spin = float(trajectory.extrema(1).peak @ turns)
    step_s = min(LONGEST_STEP_S, SLACK_SHARE * constraint.angle_rad / max(spin, 1e-12))
    t0, t1 = float(trajectory.knots[0]), float(trajectory.knots[-1])
    times = np.linspace(t0, t1, min(MOST_SAMPLES, math.ceil((t1 - t0) / step_s) + 1))
    angles = constraint.angles(ck.frame_poses(robot, trajectory(times), frame)[:, :3, :3], reference)
    turning = trajectory.speed_bounds(times) @ turns
    dt = np.diff(times)
    return OrientationDeviation(
        angle_rad=float(np.max(0.5 * (angles[:-1] + angles[1:] + turning * dt))),
        sampled_angle_rad=float(angles.max()),
        worst_time_s=float(times[int(np.argmax(angles))]),
        step_s=float(dt.max()),
    )
