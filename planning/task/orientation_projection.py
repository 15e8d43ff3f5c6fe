"""Configurations moved the least onto an orientation constraint: Newton's method on the frame's Jacobian.

A configuration whose constraint angle exceeds :data:`AIM_SHARE` of the allowed one is turned
back to that share by damped least squares on the frame's world-aligned angular Jacobian
(less its turn about the free axis, where one is free), within the joint ranges; with
``keep_position`` the frame's origin is held where it was too, weighed by
:data:`HOLD_POSITION_M` (the wrist turns rather than the arm). The set of configurations
within that share is the manifold a constrained motion is planned on; the motion's certified
angle must stay within the whole allowed one.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.kinematics.numerical_ik import damped_step
from planning.task.orientation import OrientationConstraint

FloatArray = NDArray[np.float64]

AIM_SHARE = 0.5
"""A configuration whose angle exceeds this share of the allowed one is turned back to it."""
HOLD_POSITION_M = 0.01
"""How far the frame's origin may leave where it was while it is turned back, weighed as the
allowed angle [m]."""
NEWTON_STEPS = 40
"""Most Newton steps of one projection."""
DAMPING = 1e-4
"""Damping of the least squares, relative to the size of the weighted Jacobian."""


class Projector:
    """Projects configurations of ``robot`` onto ``constraint`` about the ``reference`` orientation.

    Args:
        robot: the robot.
        frame: the constrained frame.
        constraint: the constraint.
        reference: ``(3, 3)`` its reference orientation in the base frame.
    """

    def __init__(
        self, robot: ck.Robot, frame: str, constraint: OrientationConstraint, reference: FloatArray
    ) -> None:
        self.robot, self.frame, self.constraint, self.reference = robot, frame, constraint, reference
        self.aim_rad = AIM_SHARE * constraint.angle_rad
        self._fid = robot.frame_id(frame)
        self._weights = np.array([1.0 / HOLD_POSITION_M] * 3 + [1.0 / constraint.angle_rad] * 3)

    def angles(self, configurations: FloatArray) -> FloatArray:
        """``(N,)`` the constraint's angle of each of ``configurations`` ``(N, nq)`` [rad]."""
        rotations = ck.frame_poses(self.robot, configurations, self.frame)[:, :3, :3]
        return self.constraint.angles(rotations, self.reference)

    def project(self, q: FloatArray, keep_position: bool = False) -> tuple[FloatArray, float]:
        """``q`` moved the least onto the manifold (see above), and its angle there [rad].

        An angle above :attr:`aim_rad` means the projection did not get there.
        """
        robot, fid = self.robot, self._fid
        lower, upper = robot.limits.lower, robot.limits.upper
        rows = slice(0, 6) if keep_position else slice(3, 6)
        where = None
        angle = math.inf
        q = np.asarray(q, dtype=float)
        for step in range(NEWTON_STEPS + 1):
            full = self._full_jacobian(q)  # and the frame's placement in data.oMf
            placement = robot.data.oMf[fid]
            if where is None:
                where = placement.translation.copy()
            error = self.constraint.error(placement.rotation, self.reference)
            angle = float(np.linalg.norm(error))
            if angle <= self.aim_rad or step == NEWTON_STEPS:
                break
            turn = error * (1.0 - 0.9 * self.aim_rad / angle)
            target = (np.concatenate([where - placement.translation, turn]) * self._weights)[rows]
            jacobian = (self._less_free_turn(full, placement.rotation) * self._weights[:, None])[rows]
            size = max(float(np.sum(jacobian * jacobian)), 1.0)
            q = np.clip(q + damped_step(jacobian, target, DAMPING * math.sqrt(size)), lower, upper)
        return q, angle

    def _full_jacobian(self, q: FloatArray) -> FloatArray:
        """``(6, nq)`` the frame's world-aligned Jacobian at ``q`` (its placement updated on the way)."""
        aligned = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        return np.array(pin.computeFrameJacobian(self.robot.model, self.robot.data, q, self._fid, aligned))

    def _less_free_turn(self, jacobian: FloatArray, rotation: FloatArray) -> FloatArray:
        """``jacobian`` with its angular rows less the turn about the free axis, if there is one."""
        free = self.constraint.free_axis
        if free is not None:
            axis = rotation[:, free]
            jacobian[3:] = (np.eye(3) - np.outer(axis, axis)) @ jacobian[3:]
        return jacobian
