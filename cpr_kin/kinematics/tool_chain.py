"""A robot's chain to a tool frame, and the compiled pieces every descent on it takes.

The tool frame's placement at a configuration (:func:`place_tool`, on
:func:`~cpr_kin.bounds.batch_kinematics.place_joints`), its geometric Jacobian in the world's
axes (:func:`tool_jacobian`, Pinocchio's ``LOCAL_WORLD_ALIGNED``), the logarithm of a rotation
(:func:`rotation_log`, Pinocchio's ``log3``): with the damped least-squares steps of
:mod:`cpr_kin.kinematics.least_squares`, what the numerical IK's descent
(:mod:`cpr_kin.kinematics.ik_descent`) and a tool line's Newton steps are made of, compiled.
"""

from __future__ import annotations

import math
import weakref
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
    def of(cls, robot: Robot, frame_name: str | None = None) -> ToolChain:
        """The chain of ``robot``'s model to ``frame_name`` (by default :attr:`Robot.tcp_frame`).

        Made once per robot and frame (the robot's model does not change); its arrays are
        shared, not to be written.
        """
        name = frame_name or robot.tcp_frame
        known = _CHAINS.setdefault(robot, {})
        if name not in known:
            known[name] = cls._made(robot, name)
        return known[name]

    @classmethod
    def _made(cls, robot: Robot, frame_name: str) -> ToolChain:
        model = robot.model
        frame = model.frames[robot.frame_id(frame_name)]
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
        """The chain's arrays and the tool's, as the compiled functions take them."""
        return self.chain.arrays, (self.tool_in_joint, self.moves_tool, self.joint)


_CHAINS: weakref.WeakKeyDictionary[Robot, dict[str, ToolChain]] = weakref.WeakKeyDictionary()
"""Each robot's chains, by frame name, for as long as the robot lives."""


@njit
def tool_poses(configurations: FloatArray, chain: ChainArrays, tool: ToolArrays) -> FloatArray:
    """``(N, 4, 4)`` the tool frame's placements in the world at ``configurations`` ``(N, nq)``."""
    joints = len(chain[0])
    work = (np.empty((joints, 3, 3)), np.empty((joints, 3)), np.empty((4, 3)))
    tool_rot, tool_pos = np.empty((3, 3)), np.empty(3)
    out = np.zeros((len(configurations), 4, 4))
    for k in range(len(configurations)):
        place_tool(configurations[k], chain, tool, work, tool_rot, tool_pos)
        for r in range(3):
            for c in range(3):
                out[k, r, c] = tool_rot[r, c]
            out[k, r, 3] = tool_pos[r]
        out[k, 3, 3] = 1.0
    return out


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
def place_tool(
    q: FloatArray,
    chain: ChainArrays,
    tool: ToolArrays,
    work: tuple[FloatArray, FloatArray, FloatArray],
    tool_rot: FloatArray,
    tool_pos: FloatArray,
) -> None:
    """Write the tool frame's rotation ``(3, 3)`` and position ``(3,)`` [m] in the world at ``q``.

    ``work`` is ``(rot, trans, local)``: every joint's placement ``(J, 3, 3)``, ``(J, 3)`` is
    written there (what :func:`tool_jacobian` reads) and ``local`` ``(4, 3)`` is scratch.
    """
    tool_in_joint, _, tool_joint = tool
    rot, trans, local = work
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


@njit_inline
def tool_jacobian(
    chain: ChainArrays,
    tool: ToolArrays,
    free: BoolArray,
    work: tuple[FloatArray, FloatArray, FloatArray],
    tool_pos: FloatArray,
    jacobian: FloatArray,
) -> None:
    """Write the tool frame's Jacobian ``(6, nq)`` in the world's axes, from :func:`place_tool`'s placements.

    A column per joint the tool hangs from and ``free`` ``(nq,)`` lets move; the others zero.
    """
    _, moves_tool, _ = tool
    index_q, prismatic, axes = chain[1], chain[2], chain[3]
    rot, trans, _ = work
    for j in range(len(index_q)):
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


@njit_inline
def rotation_error(
    tool_rot: FloatArray, target_rot: FloatArray, relative: FloatArray, out: FloatArray
) -> float:
    """Write the rotation from ``tool_rot`` to ``target_rot`` in the world's axes into ``out`` ``(3,)`` [rad].

    ``tool_rot @ log3(tool_rot^T target_rot)``: what a ``LOCAL_WORLD_ALIGNED`` Jacobian's angular
    rows move. ``relative`` ``(3, 3)`` is scratch. Returns the rotation's angle [rad].
    """
    for r in range(3):
        for c in range(3):
            relative[r, c] = (
                tool_rot[0, r] * target_rot[0, c]
                + tool_rot[1, r] * target_rot[1, c]
                + tool_rot[2, r] * target_rot[2, c]
            )
    angle = rotation_log(relative, out)  # in the tool's axes; then turned into the world's
    l0, l1, l2 = out[0], out[1], out[2]
    for r in range(3):
        out[r] = tool_rot[r, 0] * l0 + tool_rot[r, 1] * l1 + tool_rot[r, 2] * l2
    return angle
