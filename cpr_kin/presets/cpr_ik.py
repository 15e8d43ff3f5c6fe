"""Analytic inverse kinematics of the CPR's tool-centre point.

The CPR is R-P-P:R-R: ``theta1`` turns everything about the vertical axis through the base,
``d2`` lifts the carriage along z and ``d3`` slides the arm radially. With the wrist angles
``theta4`` and ``theta5`` held fixed, the TCP in the turning frame is therefore

    tcp_in_column(d2, d3) = (a + d3, b, c + d2),

where ``(a, b, c)`` is the TCP at ``theta1 = d2 = d3 = 0`` for those wrist angles, read from
the model's forward kinematics (not hard-coded). In the world frame the point is rotated by
``theta1`` about z. Given a target ``(x, y, z)``:

    d2 = z - c,    a + d3 = +sqrt(x^2 + y^2 - b^2),    theta1 = atan2(y, x) - atan2(b, a + d3).

The second root ``a + d3 = -sqrt(...)`` reaches the point with the arm turned half a turn;
it is returned only when it is within the limits and the first is not.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.errors import CprKinError, JointLimitError, UnreachableError
from cpr_kin.kinematics.forward import frame_positions
from cpr_kin.model.robot import Robot

FloatArray = NDArray[np.float64]

WRIST_JOINTS = ("theta4", "theta5")
"""The CPR's wrist roll and tool pitch: held by a plan unless its start and goal differ in them, and
by a ``tcp`` goal at the values it gives (default 0; the paper holds both at 0)."""


def _wrap(angle: float) -> float:
    """Angle wrapped into (-pi, pi] [rad]."""
    return math.atan2(math.sin(angle), math.cos(angle))


def tcp_ik(robot: Robot, tcp_in_world: ArrayLike, theta4: float = 0.0, theta5: float = 0.0) -> FloatArray:
    """Joint vector that puts the TCP at ``tcp_in_world`` with the given wrist angles.

    Args:
        robot: the CPR.
        tcp_in_world: target TCP position ``(x, y, z)`` [m].
        theta4: wrist roll held during the motion [rad] (the paper: 0).
        theta5: tool pitch held during the motion [rad] (the paper: 0).

    Returns:
        ``q = (theta1, d2, d3, theta4, theta5)`` [rad, m].

    Raises:
        UnreachableError: the target needs a joint outside its limits; the message names
            the joint, the value it would need and its range.
        CprKinError: the target is not three finite numbers.

    """
    try:
        target = np.asarray(tcp_in_world, dtype=float)
    except (TypeError, ValueError):
        raise CprKinError(f"TCP target {tcp_in_world!r} must be three numbers (x, y, z) [m]") from None
    if target.shape != (3,) or not np.all(np.isfinite(target)):
        raise CprKinError(
            f"TCP target {np.asarray(tcp_in_world).tolist()} must be three finite numbers (x, y, z) [m]"
        )
    for name, value in (("theta4", theta4), ("theta5", theta5)):
        robot.check_joint(name, value)

    a, b, c = frame_positions(robot, [0.0, 0.0, 0.0, theta4, theta5])
    x, y, z = target
    rho_sq = x * x + y * y
    if rho_sq < b * b:
        raise UnreachableError(
            f"TCP target {target.tolist()} is {math.sqrt(rho_sq):.4g} m from the column axis; "
            f"with theta4 = {theta4:g}, theta5 = {theta5:g} rad the TCP cannot come closer "
            f"than {abs(b):.4g} m"
        )
    radial = math.sqrt(rho_sq - b * b)
    d2 = z - c
    candidates = []
    for sign in (1.0, -1.0):
        d3 = sign * radial - a
        theta1 = _wrap(math.atan2(y, x) - math.atan2(b, sign * radial))
        candidates.append(np.array([theta1, d2, d3, theta4, theta5]))
    first_error: JointLimitError | None = None
    for q in candidates:
        try:
            return robot.configuration(q)
        except JointLimitError as exc:
            first_error = first_error or exc
    raise UnreachableError(f"TCP target {target.tolist()} is out of reach: {first_error}") from None


def position_ik(robot: Robot, tcp_in_base: FloatArray, held: Mapping[str, float]) -> FloatArray:
    """:func:`tcp_ik` as the CPR preset's :class:`~cpr_kin.PositionIk` (held wrist angles, default 0).

    Raises:
        UnreachableError: the target is out of reach, or ``held`` names a joint other than the
            wrist's (this IK holds only those: the caller falls back to the numerical IK).
    """
    others = sorted(set(held) - set(WRIST_JOINTS))
    if others:
        raise UnreachableError(f"the CPR's analytic IK holds only {list(WRIST_JOINTS)}, not {others}")
    return tcp_ik(robot, tcp_in_base, held.get("theta4", 0.0), held.get("theta5", 0.0))
