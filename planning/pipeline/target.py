"""A start or goal: a joint vector, a tool position, or a tool pose, solved and verified.

- ``q``: the planned joints' values [rad, m], as a list in their order or a
  ``{joint: value}`` map naming every one;
- ``tcp``: the tool frame's position [m] (a position goal); on the CPR its analytic IK with
  the wrist angles ``theta4``, ``theta5`` held, else the numerical IK;
- ``pose``: the tool frame's position [m] and orientation (a pose goal), by the numerical IK
  (:func:`cpr_kin.solve_ik`).

Every IK result is checked by forward kinematics against the target and its tolerance
(``tolerance_m``, ``tolerance_rad``); the analytic IK's too (a CPR variant whose axes it does
not model falls back to the numerical one).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

import cpr_kin as ck
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]

DEFAULT_TOLERANCE_M = 1e-4
"""Largest position error of an IK solution unless a target says otherwise [m]."""
DEFAULT_TOLERANCE_RAD = 1e-3
"""Largest orientation error of an IK solution unless a target says otherwise [rad]."""
TOLERANCE_M_RANGE = (1e-9, 0.1)
"""Position tolerances a target may give [m]."""
TOLERANCE_RAD_RANGE = (1e-9, 0.5)
"""Orientation tolerances a target may give [rad]."""
SAME_Q_TOLERANCE = 1e-6
"""Largest difference in a joint [rad or m] at which a configuration meets a joint-vector target."""


@dataclass(frozen=True)
class Target:
    """A start or goal (module docstring).

    Attributes:
        tcp: ``(x, y, z)`` of the tool frame [m], or ``None``.
        q: the planned joints' values [rad, m], a tuple in their order or a ``{joint: value}``
            map, or ``None``.
        theta4: the CPR's wrist roll held with ``tcp`` [rad].
        theta5: the CPR's tool pitch held with ``tcp`` [rad].
        pose: ``(position (3,), rotation (3, 3))`` of the tool frame [m], or ``None``.
        tolerance_m: largest position error of an IK solution [m].
        tolerance_rad: largest rotation error of a pose's IK solution [rad].
    """

    tcp: tuple[float, float, float] | None = None
    q: tuple[float, ...] | Mapping[str, float] | None = None
    theta4: float = 0.0
    theta5: float = 0.0
    pose: tuple[tuple[float, ...], tuple[tuple[float, ...], ...]] | None = field(default=None)
    tolerance_m: float = DEFAULT_TOLERANCE_M
    tolerance_rad: float = DEFAULT_TOLERANCE_RAD

    def __post_init__(self) -> None:
        given = [name for name in ("tcp", "q", "pose") if getattr(self, name) is not None]
        if len(given) != 1:
            raise PlanningError(
                f"a start or goal needs exactly one of 'q' (joint values), 'tcp' (x, y, z), 'pose': {given}"
            )
        if not (self.tolerance_m > 0 and self.tolerance_rad > 0):
            raise PlanningError(f"tolerances {self.tolerance_m} m, {self.tolerance_rad} rad must be > 0")

    @property
    def ik_target(self) -> ck.IkTarget | None:
        """The tool frame's target, or ``None`` for a joint vector."""
        if self.tcp is not None:
            return ck.IkTarget(np.asarray(self.tcp, dtype=float), None, self.tolerance_m, self.tolerance_rad)
        if self.pose is not None:
            position, rotation = self.pose
            return ck.IkTarget(
                np.asarray(position), np.asarray(rotation), self.tolerance_m, self.tolerance_rad
            )
        return None

    def configuration(
        self,
        robot: ck.Robot,
        seed_q: FloatArray | None = None,
        accept: Callable[[FloatArray], bool] | None = None,
    ) -> FloatArray:
        """The joint vector [rad, m], verified; IK solutions near ``seed_q``, ``accept``-ed ones first.

        Raises:
            cpr_kin.JointLimitError: a joint vector outside the limits, of the wrong length or
                naming the wrong joints.
            cpr_kin.IkMissError: a ``tcp`` or ``pose`` no configuration reaches within the
                tolerance (the message says how close the IK came).
            PlanningError: ``theta4``/``theta5`` given for a robot without the CPR's joints.
        """
        if self.q is not None:
            values = dict(self.q) if isinstance(self.q, Mapping) else np.asarray(self.q, dtype=float)
            return robot.configuration(values)
        target = self.ik_target
        assert target is not None  # exactly one of q, tcp, pose (__post_init__)
        if self.tcp is None or robot.joint_names != ck.CPR_JOINTS:
            if self.theta4 or self.theta5:
                raise PlanningError(
                    f"theta4 = {self.theta4}, theta5 = {self.theta5}: these are the CPR's wrist angles; "
                    f"this robot's joints are {list(robot.joint_names)} (give a 'pose' or 'q' instead)"
                )
            return ck.solve_ik(robot, target, seed_q, accept)
        try:  # the CPR's analytic IK, verified; else (a variant it does not model) the numerical one
            q = ck.tcp_ik(robot, self.tcp, self.theta4, self.theta5)
            analytic = self.miss(robot, q)
        except ck.UnreachableError as exc:
            analytic = str(exc)
        if analytic is None:
            return q
        seed = np.array(seed_q if seed_q is not None else (robot.limits.lower + robot.limits.upper) / 2)
        seed[_wrist(robot)] = (self.theta4, self.theta5)
        try:
            return ck.solve_ik(robot, target, seed, accept, held=robot.wrist_joints)
        except ck.IkMissError as exc:
            raise ck.IkMissError(f"{exc}; the analytic IK: {analytic}") from None

    def miss(self, robot: ck.Robot, q: FloatArray) -> str | None:
        """How ``q`` misses this target, or ``None`` if it meets it (forward kinematics for a tool target).

        A joint vector is met within :data:`SAME_Q_TOLERANCE` per joint; a ``tcp`` or ``pose``
        within the target's tolerances, and a ``tcp`` on the CPR holds the wrist angles too.
        """
        q = np.asarray(q, dtype=float)
        if self.q is not None:
            wanted = self.configuration(robot)
            gap = float(np.abs(q - wanted).max())
            return None if gap <= SAME_Q_TOLERANCE else f"{gap:.3g} away from its joint values"
        target = self.ik_target
        assert target is not None  # exactly one of q, tcp, pose (__post_init__)
        placement = pin.SE3(ck.frame_poses(robot, q[None])[0])
        if not target.reached(placement):
            return f"{target.miss(placement)} of frame '{robot.tcp_frame}'"
        if self.tcp is not None and robot.joint_names == ck.CPR_JOINTS:
            gap = float(np.abs(q[_wrist(robot)] - (self.theta4, self.theta5)).max())
            if gap > SAME_Q_TOLERANCE:
                return f"its wrist angles {list(robot.wrist_joints)} are {gap:.3g} rad from the target's"
        return None


def _wrist(robot: ck.Robot) -> list[int]:
    """Indices of the CPR preset's wrist joints (:attr:`cpr_kin.Robot.wrist_joints`) in ``q``."""
    return [robot.limits.index(name) for name in robot.wrist_joints]
