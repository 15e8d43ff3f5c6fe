"""One start of the numerical IK's damped least-squares descent, compiled.

:func:`~cpr_kin.kinematics.numerical_ik.solve_ik` descends from tens of starts a target, and
each start takes up to a hundred steps: in Python, with Pinocchio's forward kinematics and
Jacobian a call each, a step costs tens of microseconds of calls for microseconds of
arithmetic. Here a whole start runs compiled on the robot's chain to its tool frame
(:mod:`cpr_kin.kinematics.tool_chain`: the frame's placement, its Jacobian in the world's
axes, the rotation error as a logarithm, the step ``S J_S^T (J_S J_S^T + lambda^2 I)^-1 e``
with ``J_S = J S`` by a Cholesky factorisation, ``S`` the joints' scales: 1 for the plain
step, the speed scales for the step least in time, 0 for a held joint); the rules are those of
``numerical_ik``'s docstring.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays
from cpr_kin.common.compiled import njit
from cpr_kin.kinematics.least_squares import damped_step, scale_columns, scale_step
from cpr_kin.kinematics.tool_chain import ToolArrays, place_tool, rotation_error, tool_jacobian

FloatArray = NDArray[np.float64]
TargetArrays = tuple[FloatArray, FloatArray, FloatArray, bool]
"""A target as compiled code takes it: position [m], rotation, tolerances [m, rad], whether a pose."""
StepArrays = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
"""How a step moves: each joint's ``scales`` (0: held), ``lower`` and ``upper`` limits, and
``[damping, max_step, progress]``."""


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
    position, rotation, tolerances, pose = target
    scales, lower, upper, rates = step
    free = scales > 0.0
    damping, max_step, progress = rates[0], rates[1], rates[2]
    iterations, patience = counts
    joints, nq, rows = len(chain[0]), len(q), 6 if pose else 3
    q = q.copy()
    work = (np.empty((joints, 3, 3)), np.empty((joints, 3)), np.empty((4, 3)))
    tool_rot, tool_pos, relative = np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    jacobian, error = np.zeros((6, nq)), np.empty(6)
    solve_work, change = (np.empty((6, 6)), np.empty(6)), np.empty(nq)
    least, stuck, steps = np.inf, 0, 0
    for _ in range(iterations):
        place_tool(q, chain, tool, work, tool_rot, tool_pos)
        for r in range(3):
            error[r] = position[r] - tool_pos[r]
        excess = math.sqrt(error[0] ** 2 + error[1] ** 2 + error[2] ** 2) / tolerances[0]
        if pose:
            angle = rotation_error(tool_rot, rotation, relative, error[3:])
            excess = max(excess, angle / tolerances[1])
        if excess <= 1.0:  # reached
            break
        if excess < (1.0 - progress) * least:
            least, stuck = excess, 0
        else:
            stuck += 1
            if stuck >= patience:
                break
        tool_jacobian(chain, tool, free, work, tool_pos, jacobian)
        scale_columns(jacobian, scales)
        damped_step(jacobian, error, rows, damping, solve_work, change)
        scale_step(change, scales)
        steps += 1
        for v in range(nq):
            q[v] = min(upper[v], max(lower[v], q[v] + min(max_step, max(-max_step, change[v]))))
    return q, steps
