"""One start of the numerical IK's damped least-squares descent, compiled.

:func:`~cpr_kin.kinematics.numerical_ik.solve_ik` descends from tens of starts a target, and
each start takes up to a hundred steps: in Python, with Pinocchio's forward kinematics and
Jacobian a call each, a step costs tens of microseconds of calls for microseconds of
arithmetic. Here a whole start runs compiled on the robot's chain
(:class:`~cpr_kin.bounds.batch_kinematics.KinematicChain`): the tool frame's placement
(:func:`~cpr_kin.bounds.batch_kinematics.place_joints`), its geometric Jacobian in the world's
axes (Pinocchio's ``LOCAL_WORLD_ALIGNED``), the rotation error as the logarithm of the relative
rotation (Pinocchio's ``log3``), and the step ``J^T (J J^T + lambda^2 I)^-1 e`` by a Cholesky
factorisation; the rules are those of ``numerical_ik``'s docstring.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays, KinematicChain, place_joints
from cpr_kin.common.compiled import njit, njit_inline
from cpr_kin.model.robot import Robot

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]
ToolArrays = tuple[FloatArray, BoolArray, int]
"""A :class:`ToolChain`'s tool, as compiled code takes it: ``tool_in_joint``, ``moves_tool``, ``joint``."""
TargetArrays = tuple[FloatArray, FloatArray, FloatArray, bool]
"""A target as compiled code takes it: position [m], rotation, tolerances [m, rad], whether a pose."""
StepArrays = tuple[BoolArray, FloatArray, FloatArray, FloatArray]
"""How a step moves: ``free`` joints, ``lower`` and ``upper`` limits, and ``[damping, max_step,
progress]``."""

NEAR_ZERO_RAD = 1e-4
"""Below this rotation angle [rad] the logarithm's factor is its series (``1/2 + theta^2/12``)."""
NEAR_PI_RAD = 1e-3
"""Within this of pi [rad] the logarithm's axis is read from the rotation's symmetric part."""


@dataclass(frozen=True)
class ToolChain:
    """A robot's chain and its tool frame, as the compiled descent takes them.

    Attributes:
        chain: the joints (:class:`~cpr_kin.bounds.batch_kinematics.KinematicChain`).
        tool_in_joint: ``(4, 3)`` the tool frame's placement in its joint: rotation rows, then
            the translation [m].
        moves_tool: ``(J,)`` whether each joint is one the tool frame hangs from.
        joint: the tool frame's joint in the chain (``-1``: fixed to the world).
    """

    chain: KinematicChain
    tool_in_joint: FloatArray
    moves_tool: BoolArray
    joint: int

    @classmethod
    def of(cls, robot: Robot) -> ToolChain:
        """The chain of ``robot``'s model to its tool frame, :attr:`Robot.tcp_frame`."""
        model = robot.model
        frame = model.frames[robot.frame_id(robot.tcp_frame)]
        parent = int(frame.parentJoint)
        moves = np.zeros(model.njoints - 1, dtype=np.bool_)
        for j in model.supports[parent]:
            if j > 0:
                moves[j - 1] = True
        placement = frame.placement
        tool = np.vstack([np.asarray(placement.rotation, dtype=float), placement.translation[None]])
        return cls(KinematicChain.from_model(model), np.ascontiguousarray(tool), moves, parent - 1)

    @property
    def arrays(self) -> tuple[ChainArrays, ToolArrays]:
        """The chain's arrays and the tool's, as :func:`descend` takes them."""
        return self.chain.arrays, (self.tool_in_joint, self.moves_tool, self.joint)


@njit_inline
def rotation_log(m: FloatArray, out: FloatArray) -> float:
    """Write the logarithm of rotation ``m`` ``(3, 3)`` into ``out`` ``(3,)`` [rad]; its angle [rad].

    The axis times the angle in ``[0, pi]``, as Pinocchio's ``log3``; near pi, where the
    antisymmetric part vanishes, the axis comes from the symmetric part, signed by what is
    left of the antisymmetric one.
    """
    v0, v1, v2 = m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]
    sine = 0.5 * math.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
    cosine = min(1.0, max(-1.0, 0.5 * (m[0, 0] + m[1, 1] + m[2, 2] - 1.0)))
    angle = math.atan2(sine, cosine)
    if angle < math.pi - NEAR_PI_RAD:
        factor = 0.5 + angle * angle / 12.0 if angle < NEAR_ZERO_RAD else 0.5 * angle / sine
        out[0], out[1], out[2] = factor * v0, factor * v1, factor * v2
        return angle
    big = 0  # the axis' largest component, from the diagonal: a_i^2 = (m_ii - cos) / (1 - cos)
    for i in range(1, 3):
        if m[i, i] > m[big, big]:
            big = i
    scale = 1.0 - cosine
    a_big = math.sqrt(max(0.0, (m[big, big] - cosine) / scale))
    for i in range(3):
        out[i] = a_big if i == big else (m[big, i] + m[i, big]) / (2.0 * scale * a_big)
    # the antisymmetric part is 2 sin(angle) a: the axis' sign is the one it leaves
    signed = -angle if out[0] * v0 + out[1] * v1 + out[2] * v2 < 0.0 else angle
    for i in range(3):
        out[i] *= signed
    return angle


@njit_inline
def damped_solve(system: FloatArray, rhs: FloatArray, size: int, out: FloatArray) -> None:
    """Write ``system^-1 rhs`` into ``out[:size]``: ``system`` ``(size, size)`` symmetric positive definite.

    Cholesky, in place in ``system``'s lower triangle, then two triangular solves.
    """
    for i in range(size):
        for j in range(i + 1):
            total = system[i, j]
            for k in range(j):
                total -= system[i, k] * system[j, k]
            system[i, j] = math.sqrt(total) if i == j else total / system[j, j]
    for i in range(size):
        total = rhs[i]
        for k in range(i):
            total -= system[i, k] * out[k]
        out[i] = total / system[i, i]
    for i in range(size - 1, -1, -1):
        total = out[i]
        for k in range(i + 1, size):
            total -= system[k, i] * out[k]
        out[i] = total / system[i, i]


@njit
def descend(
    q: FloatArray,
    chain: ChainArrays,
    tool: ToolArrays,
    target: TargetArrays,
    step: StepArrays,
    counts: tuple[int, int],
) -> tuple[FloatArray, int]:
    """One start's descent from ``q`` ``(nq,)``: the configuration it ends at [rad, m], and its steps.

    It ends where the target is reached (the larger of the position and rotation errors, each
    over its tolerance, at most 1), after ``counts[0]`` steps, or once ``counts[1]`` steps in
    a row have not made the least error ``progress`` smaller (``numerical_ik``).
    """
    tool_in_joint, moves_tool, tool_joint = tool
    position, rotation, tolerances, pose = target
    free, lower, upper, rates = step
    damping, max_step, progress = rates[0], rates[1], rates[2]
    iterations, patience = counts
    joints, nq, rows = len(chain[0]), len(q), 6 if pose else 3
    index_q, prismatic, axes = chain[1], chain[2], chain[3]
    q = q.copy()
    rot, trans, local = np.empty((joints, 3, 3)), np.empty((joints, 3)), np.empty((4, 3))
    tool_rot, tool_pos = np.empty((3, 3)), np.empty(3)
    relative, log = np.empty((3, 3)), np.empty(3)
    jacobian, error = np.zeros((6, nq)), np.empty(6)
    system, solved = np.empty((6, 6)), np.empty(6)
    least, stuck, steps = np.inf, 0, 0
    for _ in range(iterations):
        place_joints(q, chain, rot, trans, local)
        for r in range(3):
            tool_pos[r] = tool_in_joint[3, r]
            for c in range(3):
                tool_rot[r, c] = tool_in_joint[r, c]
            if tool_joint >= 0:
                tool_pos[r] = trans[tool_joint, r]
                for c in range(3):
                    tool_pos[r] += rot[tool_joint, r, c] * tool_in_joint[3, c]
                    tool_rot[r, c] = (
                        rot[tool_joint, r, 0] * tool_in_joint[0, c]
                        + rot[tool_joint, r, 1] * tool_in_joint[1, c]
                        + rot[tool_joint, r, 2] * tool_in_joint[2, c]
                    )
        for r in range(3):
            error[r] = position[r] - tool_pos[r]
        excess = math.sqrt(error[0] ** 2 + error[1] ** 2 + error[2] ** 2) / tolerances[0]
        if pose:  # the rotation from the tool's to the target's, in the world's axes
            for r in range(3):
                for c in range(3):
                    relative[r, c] = (
                        tool_rot[0, r] * rotation[0, c]
                        + tool_rot[1, r] * rotation[1, c]
                        + tool_rot[2, r] * rotation[2, c]
                    )
            excess = max(excess, rotation_log(relative, log) / tolerances[1])
            for r in range(3):
                error[3 + r] = tool_rot[r, 0] * log[0] + tool_rot[r, 1] * log[1] + tool_rot[r, 2] * log[2]
        if excess <= 1.0:  # reached
            break
        if excess < (1.0 - progress) * least:
            least, stuck = excess, 0
        else:
            stuck += 1
            if stuck >= patience:
                break
        for j in range(joints):  # a column per joint the tool hangs from and the descent moves
            v = index_q[j]
            for r in range(6):
                jacobian[r, v] = 0.0
            if not (moves_tool[j] and free[v]):
                continue
            x, y, z = axes[j, 0], axes[j, 1], axes[j, 2]  # the joint's axis in the world's axes
            w0 = rot[j, 0, 0] * x + rot[j, 0, 1] * y + rot[j, 0, 2] * z
            w1 = rot[j, 1, 0] * x + rot[j, 1, 1] * y + rot[j, 1, 2] * z
            w2 = rot[j, 2, 0] * x + rot[j, 2, 1] * y + rot[j, 2, 2] * z
            if prismatic[j]:
                jacobian[0, v], jacobian[1, v], jacobian[2, v] = w0, w1, w2
            else:
                d0, d1, d2 = tool_pos[0] - trans[j, 0], tool_pos[1] - trans[j, 1], tool_pos[2] - trans[j, 2]
                jacobian[0, v], jacobian[1, v] = w1 * d2 - w2 * d1, w2 * d0 - w0 * d2
                jacobian[2, v] = w0 * d1 - w1 * d0
                jacobian[3, v], jacobian[4, v], jacobian[5, v] = w0, w1, w2
        for r in range(rows):
            for c in range(r + 1):
                total = damping * damping if r == c else 0.0
                for v in range(nq):
                    total += jacobian[r, v] * jacobian[c, v]
                system[r, c] = total
                system[c, r] = total
        damped_solve(system, error, rows, solved)
        steps += 1
        for v in range(nq):
            change = 0.0
            for r in range(rows):
                change += jacobian[r, v] * solved[r]
            change = min(max_step, max(-max_step, change))
            q[v] = min(upper[v], max(lower[v], q[v] + change))
    return q, steps
