"""A start or goal: a joint vector, a tool position, or a tool pose, solved and verified.

- ``q``: the planned joints' values [rad, m], as a list in their order or a
  ``{joint: value}`` map naming every one;
- ``tcp``: the tool frame's position [m] (a position goal), with the joints ``hold`` names
  at those values and the robot's wrist joints (:attr:`cpr_kin.Robot.wrist_joints`) at 0
  unless named: the robot's own IK (:attr:`cpr_kin.Robot.position_ik`, a preset's analytic
  one) where it has one, else the numerical IK;
- ``pose``: the tool frame's position [m] and orientation (a pose goal), by the numerical IK
  (:func:`cpr_kin.solve_ik`).

Every IK result is checked by forward kinematics against the target and its tolerance
(``tolerance_m``, ``tolerance_rad``) and the held joints; the robot's own IK's too (a variant
whose axes it does not model falls back to the numerical one).
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
        hold: planned joints held at these values by a ``tcp`` target [rad, m] (the robot's
            wrist joints at 0 unless named here).
        pose: ``(position (3,), rotation (3, 3))`` of the tool frame [m], or ``None``.
        tolerance_m: largest position error of an IK solution [m].
        tolerance_rad: largest rotation error of a pose's IK solution [rad].
    """

    tcp: tuple[float, float, float] | None = None
    q: tuple[float, ...] | Mapping[str, float] | None = None
    hold: Mapping[str, float] = field(default_factory=dict)
    pose: tuple[tuple[float, ...], tuple[tuple[float, ...], ...]] | None = field(default=None)
    tolerance_m: float = DEFAULT_TOLERANCE_M
    tolerance_rad: float = DEFAULT_TOLERANCE_RAD

    def __post_init__(self) -> None:
        given = [name for name in ("tcp", "q", "pose") if getattr(self, name) is not None]
        if len(given) != 1:
            raise PlanningError(
                f"a start or goal needs exactly one of 'q' (joint values), 'tcp' (x, y, z), 'pose': {given}"
            )
        if self.hold and self.tcp is None:
            raise PlanningError(f"hold = {dict(self.hold)}: joints are held with a 'tcp' target only")
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
        prefer: Callable[[FloatArray], bool] | None = None,
    ) -> FloatArray:
        """The joint vector [rad, m], verified; IK solutions near ``seed_q``, ``accept``-ed ones first.

        Of the accepted solutions, those ``prefer`` passes come first
        (:func:`cpr_kin.solve_ik`). The robot's own analytic IK, where it has one, gives its
        one solution whatever the tests say.

        Raises:
            cpr_kin.JointLimitError: a joint vector outside the limits, of the wrong length or
                naming the wrong joints.
            cpr_kin.IkMissError: a ``tcp`` or ``pose`` no configuration reaches within the
                tolerance (the message says how close the IK came).
            PlanningError: ``hold`` names a joint the robot does not plan.
        """
        if self.q is not None:
            values = dict(self.q) if isinstance(self.q, Mapping) else np.asarray(self.q, dtype=float)
            return robot.configuration(values)
        target = self.ik_target
        assert target is not None  # exactly one of q, tcp, pose (__post_init__)
        held = self.held(robot) if self.tcp is not None else {}
        own = ""
        if self.tcp is not None and robot.position_ik is not None:  # the robot's own IK, verified
            try:
                q = robot.position_ik(robot, np.asarray(self.tcp, dtype=float), held)
                own = self.miss(robot, q) or ""
            except ck.UnreachableError as exc:
                own = str(exc)
            if not own:
                return q
        if not held:
            return ck.solve_ik(robot, target, seed_q, accept, prefer=prefer)
        seed = np.array(seed_q if seed_q is not None else (robot.limits.lower + robot.limits.upper) / 2)
        for name, value in held.items():
            seed[robot.limits.index(name)] = value
        try:
            return ck.solve_ik(robot, target, seed, accept, held=tuple(held), prefer=prefer)
        except ck.IkMissError as exc:
            raise ck.IkMissError(f"{exc}; the robot's analytic IK: {own}" if own else str(exc)) from None

    def held(self, robot: ck.Robot) -> dict[str, float]:
        """The joints a ``tcp`` target holds [rad, m]: ``hold``, and the robot's wrist joints at 0.

        Raises:
            PlanningError: ``hold`` names a joint the robot does not plan.
            cpr_kin.JointLimitError: a held value outside its joint's range.
        """
        unknown = sorted(set(self.hold) - set(robot.joint_names))
        if unknown:
            raise PlanningError(
                f"hold = {dict(self.hold)}: {unknown} not planned joint(s) of this robot; "
                f"its planned joints are {list(robot.joint_names)}"
            )
        for name, value in self.hold.items():
            robot.check_joint(name, value)
        return {name: 0.0 for name in robot.wrist_joints} | {k: float(v) for k, v in self.hold.items()}

    def miss(self, robot: ck.Robot, q: FloatArray) -> str | None:
        """How ``q`` misses this target, or ``None`` if it meets it (forward kinematics for a tool target).

        A joint vector is met within :data:`SAME_Q_TOLERANCE` per joint; a ``tcp`` or ``pose``
        within the target's tolerances, and a ``tcp`` holds its held joints (:meth:`held`) too.
        """
        q = np.asarray(q, dtype=float)
        if self.q is not None:
            apart = np.abs(q - self.configuration(robot))
            worst = int(np.argmax(apart))
            if apart[worst] <= SAME_Q_TOLERANCE:
                return None
            name = robot.limits.names[worst]
            unit = robot.joint_unit(name)
            tolerance = f"(tolerance {SAME_Q_TOLERANCE:g} {unit})"
            return f"{apart[worst]:.4g} {unit} from the value of joint '{name}' {tolerance}"
        target = self.ik_target
        assert target is not None  # exactly one of q, tcp, pose (__post_init__)
        placement = pin.SE3(ck.frame_poses(robot, q[None])[0])
        if not target.reached(placement):
            return f"{target.miss(placement)} of frame '{robot.tcp_frame}'"
        if self.tcp is not None:
            held = self.held(robot)
            gaps = {name: abs(q[robot.limits.index(name)] - value) for name, value in held.items()}
            off = {name: round(float(gap), 6) for name, gap in gaps.items() if gap > SAME_Q_TOLERANCE}
            if off:
                return f"its held joints are off their values by {off}"
        return None
