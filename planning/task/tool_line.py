"""A straight tool line: where the tool frame goes, along which line, within what deviation.

The line runs from the tool frame's pose at the start configuration to a goal pose: the
position moves along the segment between them, the orientation turns by the slerp between
them, both at the same progress ``sigma`` in [0, 1]. The goal is a pose in the robot's base
frame (:attr:`ToolLine.to`) or an offset of the start pose (:attr:`ToolLine.by`, in the tool's
frame or the base's: ``by: [0, 0, -0.1]`` in the tool frame is "10 cm along the tool's
z axis", the approach of a gripper).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from planning.errors import PlanningError
from planning.task.limits import (
    COARSEST_ANGLE_RAD,
    COARSEST_POSITION_M,
    FASTEST_TOOL_M_S,
    FINEST_ANGLE_RAD,
    FINEST_POSITION_M,
    LINE_ANGLE_RAD,
    LINE_POSITION_M,
    SHORTEST_LINE_M,
    SHORTEST_TURN_RAD,
)
from planning.validation import number_in, unit_quaternion

FloatArray = NDArray[np.float64]

TOOL_FRAME = "tool"
"""``ToolLine.offset_frame``: the offset is in the tool frame at the start."""
BASE_FRAME = "base"
"""``ToolLine.offset_frame``: the offset is in the robot's base frame."""


@dataclass(frozen=True)
class ToolPose:
    """A pose of the tool frame in the robot's base frame.

    Attributes:
        xyz: ``(3,)`` position [m].
        quat_xyzw: ``(4,)`` orientation as a unit quaternion ``(x, y, z, w)``.
    """

    xyz: tuple[float, float, float]
    quat_xyzw: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 1.0)

    def __post_init__(self) -> None:
        xyz = np.asarray(self.xyz, dtype=float)
        quat = np.asarray(self.quat_xyzw, dtype=float)
        if xyz.shape != (3,) or not np.isfinite(xyz).all():
            raise PlanningError(
                f"pose xyz = {np.asarray(self.xyz).tolist()}; expected three finite numbers [m]"
            )
        if quat.shape != (4,) or not np.isfinite(quat).all():
            raise PlanningError(
                f"pose quat_xyzw = {quat.tolist()}; expected four finite numbers (x, y, z, w)"
            )
        try:
            unit = unit_quaternion(quat.tolist())
        except ValueError as exc:
            raise PlanningError(f"pose quat_xyzw = {quat.tolist()} {exc}") from None
        object.__setattr__(self, "xyz", tuple(float(v) for v in xyz))
        object.__setattr__(self, "quat_xyzw", unit)

    @classmethod
    def of(cls, placement: pin.SE3) -> ToolPose:
        """The pose of a Pinocchio placement."""
        quat = pin.Quaternion(placement.rotation).coeffs()  # (x, y, z, w)
        x, y, z = (float(v) for v in placement.translation)
        qx, qy, qz, qw = (float(v) for v in quat)
        return cls((x, y, z), (qx, qy, qz, qw))

    def placement(self) -> pin.SE3:
        """The pose as a Pinocchio placement."""
        x, y, z, w = self.quat_xyzw
        return pin.SE3(pin.Quaternion(w, x, y, z).toRotationMatrix(), np.array(self.xyz))


@dataclass(frozen=True)
class LineTolerance:
    """How far the tool may leave its line at any instant of the timed motion.

    Attributes:
        position_m: largest distance of the tool frame's origin from the segment [m].
        angle_rad: largest rotation between the tool frame and the line's orientation at the
            same progress [rad].
    """

    position_m: float = LINE_POSITION_M
    angle_rad: float = LINE_ANGLE_RAD

    def __post_init__(self) -> None:
        number_in("line tolerance position_m", self.position_m, FINEST_POSITION_M, COARSEST_POSITION_M, "m")
        number_in("line tolerance angle_rad", self.angle_rad, FINEST_ANGLE_RAD, COARSEST_ANGLE_RAD, "rad")


@dataclass(frozen=True)
class ToolLine:
    """A straight motion of the tool frame, to a pose or by an offset.

    Attributes:
        frame: the tool frame (a frame of the robot's model); ``None``: the robot's tool frame.
        to: the goal pose in the base frame; exactly one of ``to`` and ``by`` is given.
        by: ``(3,)`` the goal's offset from the start position [m], in ``offset_frame``; the
            orientation is kept.
        offset_frame: :data:`TOOL_FRAME` (the tool's axes at the start) or :data:`BASE_FRAME`.
        tolerance: the deviation allowed at every instant.
        tool_speed_m_s: the largest speed of the tool frame's origin [m/s]; ``None``: only the
            joints' limits bind.
    """

    frame: str | None = None
    to: ToolPose | None = None
    by: tuple[float, float, float] | None = None
    offset_frame: str = TOOL_FRAME
    tolerance: LineTolerance = field(default_factory=LineTolerance)
    tool_speed_m_s: float | None = None

    def __post_init__(self) -> None:
        if (self.to is None) == (self.by is None):
            raise PlanningError("a tool line needs exactly one of 'to' (a pose) and 'by' (an offset [m])")
        if self.by is not None:
            by = np.asarray(self.by, dtype=float)
            if by.shape != (3,) or not np.isfinite(by).all():
                raise PlanningError(
                    f"line offset by = {np.asarray(self.by).tolist()}; expected three finite numbers [m]"
                )
            object.__setattr__(self, "by", tuple(float(v) for v in by))
        if self.offset_frame not in (TOOL_FRAME, BASE_FRAME):
            raise PlanningError(
                f"line offset frame {self.offset_frame!r} is not one of {TOOL_FRAME!r}, {BASE_FRAME!r}"
            )
        if self.tool_speed_m_s is not None:
            number_in("line tool_speed_m_s", self.tool_speed_m_s, 0.0, FASTEST_TOOL_M_S, "m/s", low_open=True)

    def goal(self, start: pin.SE3) -> pin.SE3:
        """The goal placement of the line that starts at ``start`` (the tool frame's placement).

        Raises:
            PlanningError: the line neither moves nor turns (:data:`SHORTEST_LINE_M`,
                :data:`SHORTEST_TURN_RAD`).
        """
        if self.to is not None:
            goal = self.to.placement()
        else:
            offset = np.asarray(self.by, dtype=float)
            shift = start.rotation @ offset if self.offset_frame == TOOL_FRAME else offset
            goal = pin.SE3(start.rotation.copy(), start.translation + shift)
        moved = float(np.linalg.norm(goal.translation - start.translation))
        turned = float(np.linalg.norm(pin.log3(start.rotation.T @ goal.rotation)))
        if moved < SHORTEST_LINE_M and turned < SHORTEST_TURN_RAD:
            raise PlanningError(
                f"the tool line moves {moved:.3g} m and turns {turned:.3g} rad; it must move at least "
                f"{SHORTEST_LINE_M:g} m or turn {SHORTEST_TURN_RAD:g} rad"
            )
        return goal


@dataclass(frozen=True)
class LineGeometry:
    """The line between two placements: ``pose(sigma)`` for a progress ``sigma`` in [0, 1].

    Attributes:
        start: the start placement.
        goal: the goal placement.
    """

    start: pin.SE3
    goal: pin.SE3

    @cached_property
    def shift_m(self) -> FloatArray:
        """``(3,)`` the translation from start to goal, in the base frame [m]."""
        return np.asarray(self.goal.translation - self.start.translation)

    @cached_property
    def turn(self) -> FloatArray:
        """``(3,)`` the rotation from start to goal as a vector in the start's frame [rad]."""
        return np.asarray(pin.log3(self.start.rotation.T @ self.goal.rotation))

    def pose(self, sigma: float) -> pin.SE3:
        """The placement at progress ``sigma``: the position along the segment, the orientation by slerp."""
        rotation = self.start.rotation @ pin.exp3(sigma * self.turn)
        return pin.SE3(rotation, self.start.translation + sigma * self.shift_m)

    def rotations(self, sigma: ArrayLike) -> FloatArray:
        """``(N, 3, 3)`` the line's orientations at the progresses ``sigma`` ``(N,)`` (Rodrigues' formula)."""
        turn = self.turn
        angle = float(np.linalg.norm(turn))
        if angle == 0.0:
            return np.broadcast_to(self.start.rotation, (len(np.atleast_1d(sigma)), 3, 3)).copy()
        x, y, z = turn / angle
        axis = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
        theta = np.atleast_1d(np.asarray(sigma, dtype=float))[:, None, None] * angle
        turned = np.eye(3) + np.sin(theta) * axis + (1.0 - np.cos(theta)) * (axis @ axis)
        return np.asarray(self.start.rotation @ turned)

    def progress(self, positions: ArrayLike, rotations: ArrayLike) -> FloatArray:
        """``(N,)`` the progress ``sigma`` of each tool placement: its projection on the line.

        The position's projection on the segment where the line moves; for a line that only
        turns, the rotation's projection on its axis. Clipped to [0, 1].
        """
        points = np.asarray(positions, dtype=float)
        shift = self.shift_m
        if float(shift @ shift) >= SHORTEST_LINE_M**2:
            sigma = (points - self.start.translation) @ shift / float(shift @ shift)
        else:
            turn = self.turn
            rotations_in_start = np.einsum("ji,njk->nik", self.start.rotation, np.asarray(rotations))
            logs = np.array([pin.log3(r) for r in rotations_in_start])
            sigma = logs @ turn / float(turn @ turn)
        return np.asarray(np.clip(sigma, 0.0, 1.0), dtype=float)
