"""Forward kinematics of any frame, for one configuration or a batch, and how far each joint moves it."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.kinematics.tool_chain import ToolChain, tool_poses
from cpr_kin.model.robot import Robot, joint_units

FloatArray = NDArray[np.float64]


def _as_batch(robot: Robot, q: ArrayLike) -> tuple[FloatArray, bool]:
    """``q`` as an ``(N, nq)`` float array, and whether the input was a single vector."""
    arr = np.asarray(q, dtype=float)
    single = arr.ndim == 1
    batch = np.atleast_2d(arr)
    if batch.ndim != 2 or batch.shape[1] != robot.nq:
        raise ValueError(f"configurations of shape {arr.shape}; expected (nq,) or (N, nq), nq = {robot.nq}")
    return batch, single


def frame_poses(robot: Robot, q: ArrayLike, frame: str | None = None) -> FloatArray:
    """Homogeneous transforms ``frame_in_world`` of ``frame`` at configuration(s) ``q``.

    Compiled on the robot's chain to the frame (:func:`~cpr_kin.kinematics.tool_chain.tool_poses`):
    Pinocchio's placements, to the rounding of their sums.

    Args:
        robot: the robot.
        q: one configuration ``(nq,)`` or a batch ``(N, nq)`` [rad, m].
        frame: any frame of the model (a link name, a joint name); default: the robot's
            tool-centre point, :attr:`Robot.tcp_frame`.

    Returns:
        ``(4, 4)`` for one configuration, ``(N, 4, 4)`` for a batch.

    """
    batch, single = _as_batch(robot, q)
    chain, tool = ToolChain.of(robot, frame).arrays
    out = tool_poses(np.ascontiguousarray(batch), chain, tool)
    return out[0] if single else out


def frame_positions(robot: Robot, q: ArrayLike, frame: str | None = None) -> FloatArray:
    """Positions ``frame_in_world`` [m] of ``frame``: ``(3,)`` or ``(N, 3)``."""
    poses = frame_poses(robot, q, frame)
    return poses[..., :3, 3]


@dataclass(frozen=True)
class FrameLevers:
    """How far each joint can move a frame's origin (:func:`frame_levers`).

    Attributes:
        levers: ``(nq,)`` per joint, a bound of the origin's speed per unit of the joint's:
            a revolute joint's distance to the origin at most [m/rad], 1 for a prismatic one
            [m/m], 0 off the frame's chain.
        turns: ``(nq,)`` 1 where a revolute joint of the chain turns the frame, else 0.
        reach_m: a bound of the origin's distance from the model's origin, in any configuration [m].
    """

    levers: FloatArray
    turns: FloatArray
    reach_m: float


def frame_levers(robot: Robot, frame: str) -> FrameLevers:
    """Each joint's lever to ``frame``'s origin, and the origin's reach (:class:`FrameLevers`).

    The offsets along the chain from a joint to the frame, added up (a joint turns an offset,
    never lengthens it), plus each prismatic joint's largest travel between them; from the
    model's origin, the reach.
    """
    model = robot.model
    placed = model.frames[robot.frame_id(frame)]
    units = joint_units(model)
    levers, turns = np.zeros(robot.nq), np.zeros(robot.nq)
    reach = float(np.linalg.norm(placed.placement.translation))
    joint = placed.parentJoint
    while joint > 0:
        index = model.joints[joint].idx_q
        prismatic = units[joint - 1] == "m"
        levers[index], turns[index] = (1.0, 0.0) if prismatic else (reach, 1.0)
        reach += float(np.linalg.norm(model.jointPlacements[joint].translation))
        if prismatic:
            reach += float(max(abs(model.lowerPositionLimit[index]), abs(model.upperPositionLimit[index])))
        joint = model.parents[joint]
    return FrameLevers(levers, turns, reach)
