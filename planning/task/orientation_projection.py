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

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.kinematics.tool_chain import ToolChain
from planning.task.orientation import OrientationConstraint
from planning.task.orientation_newton import project_on_constraint, project_steps

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
        self._chain = ToolChain.of(robot, frame).arrays
        self._reference = np.ascontiguousarray(reference, dtype=float)
        weights = np.array([1.0 / HOLD_POSITION_M] * 3 + [1.0 / constraint.angle_rad] * 3)
        bounds = (np.asarray(robot.limits.lower, dtype=float), np.asarray(robot.limits.upper, dtype=float))
        free = -1 if constraint.free_axis is None else constraint.free_axis
        self._rules, self._rules_keeping = (
            (weights, *bounds, np.array([self.aim_rad, free, keep, DAMPING, NEWTON_STEPS], dtype=float))
            for keep in (0.0, 1.0)
        )

    @classmethod
    def from_start(cls, robot: ck.Robot, constraint: OrientationConstraint, q_start: FloatArray) -> Projector:
        """The projector of a motion that starts at ``q_start``.

        ``constraint``'s frame (the robot's tool frame where it names none); its reference that
        frame's orientation at ``q_start`` where it names none.
        """
        frame = constraint.frame or robot.tcp_frame
        held = constraint.about(ck.frame_poses(robot, np.asarray(q_start)[None], frame)[0][:3, :3])
        return cls(robot, frame, held, held.reference())

    def angles(self, configurations: FloatArray) -> FloatArray:
        """``(N,)`` the constraint's angle of each of ``configurations`` ``(N, nq)`` [rad]."""
        rotations = ck.frame_poses(self.robot, configurations, self.frame)[:, :3, :3]
        return self.constraint.angles(rotations, self.reference)

    def project(self, q: FloatArray, keep_position: bool = False) -> tuple[FloatArray, float]:
        """``q`` moved the least onto the manifold (see above), and its angle there [rad].

        An angle above :attr:`aim_rad` means the projection did not get there. Compiled:
        :func:`~planning.task.orientation_newton.project_on_constraint`.
        """
        rules = self._rules_keeping if keep_position else self._rules
        return project_on_constraint(np.asarray(q, dtype=float), *self._chain, self._reference, rules)

    def steps(
        self, q: FloatArray, aim: FloatArray, step_m: float, range_m: float, count: int, radii: FloatArray
    ) -> tuple[FloatArray, bool, float]:
        """Up to ``count`` steps from ``q`` toward ``aim``, each projected; whether the walk got stuck.

        Each step aims ``step_m`` of robot motion (``sum_j radii_j |dq_j|`` [m]) along the
        straight line to ``aim`` and is projected; the walk is stuck where a projection does not
        get there, jumps more than twice a step, or comes no closer to ``aim``, and ends at
        ``aim`` or after ``range_m`` of motion. Returns the steps ``(n, nq)``, stuck, and the
        motion travelled [m] (:func:`~planning.task.orientation_newton.project_steps`).
        """
        walk = np.concatenate([[step_m, range_m, float(count)], radii])
        steps, n, stuck, travelled = project_steps(
            np.asarray(q, dtype=float),
            np.asarray(aim, dtype=float),
            *self._chain,
            self._reference,
            self._rules,
            walk,
        )
        return steps[:n], stuck, travelled
