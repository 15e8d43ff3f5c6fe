"""Forward kinematics of any frame, for one configuration or a batch."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from cpr_kin.model.robot import Robot

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

    Args:
        robot: the robot.
        q: one configuration ``(nq,)`` or a batch ``(N, nq)`` [rad, m].
        frame: any frame of the model (a link name, a joint name); default: the robot's
            tool-centre point, :attr:`Robot.tcp_frame`.

    Returns:
        ``(4, 4)`` for one configuration, ``(N, 4, 4)`` for a batch.

    """
    fid = robot.frame_id(robot.tcp_frame if frame is None else frame)
    batch, single = _as_batch(robot, q)
    model, data = robot.model, robot.data
    out = np.empty((len(batch), 4, 4))
    for k, qk in enumerate(batch):
        pin.forwardKinematics(model, data, qk)
        out[k] = pin.updateFramePlacement(model, data, fid).homogeneous
    return out[0] if single else out


def frame_positions(robot: Robot, q: ArrayLike, frame: str | None = None) -> FloatArray:
    """Positions ``frame_in_world`` [m] of ``frame``: ``(3,)`` or ``(N, 3)``."""
    poses = frame_poses(robot, q, frame)
    return poses[..., :3, 3]
