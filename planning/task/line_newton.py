"""A tool line's Newton corrector, compiled: one sample of the walk put on the line's pose.

:mod:`planning.task.line_ik` walks a line in hundreds of small steps, and after each predicted
step Newton's method with damped least squares puts the tool frame on the line's pose there.
In Python each Newton step is three Pinocchio calls and a small solve, tens of microseconds of
calls for microseconds of arithmetic; here a sample's whole correction runs compiled on the
robot's chain to the frame (:mod:`cpr_kin.kinematics.tool_chain`). The rules are
those of :mod:`planning.task.line_ik`.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays
from cpr_kin.common.compiled import njit
from cpr_kin.kinematics.least_squares import damped_step, scale_columns, scale_step, weighted_damping
from cpr_kin.kinematics.tool_chain import ToolArrays, place_tool, rotation_error, tool_jacobian

FloatArray = NDArray[np.float64]
PoseArrays = tuple[FloatArray, FloatArray]
"""A pose as compiled code takes it: position ``(3,)`` [m] and rotation ``(3, 3)``, in the world."""
NewtonRules = tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]
"""How the corrector steps and stops: ``weights`` ``(6,)`` (one over each tolerance), the joints'
``scales`` ``(nq,)`` (their speed scales: each step the least in time), ``lower`` and ``upper``
``(nq,)`` [rad, m], and ``[damping, progress, settled, steps]``."""


@njit
def newton_to_pose(
    q: FloatArray, chain: ChainArrays, tool: ToolArrays, target: PoseArrays, rules: NewtonRules
) -> tuple[FloatArray, float]:
    """The configuration near ``q`` ``(nq,)`` that puts the tool at ``target``, and its weighted error.

    Each step measures the weighted error (the position and the rotation's logarithm in the
    world's axes, times ``weights``; its size the larger of the two norms) and stops once it
    is at most ``settled`` or no longer ``progress`` smaller than the step before (the error
    returned is then the last that was); otherwise it moves by the damped least-squares step
    of the weighted Jacobian, ``lambda = damping * sqrt(max(trace(J J^T), 1))``, its columns
    then times ``scales`` (and the step scaled back), into ``[lower, upper]``; ``steps`` at
    most.
    """
    position, rotation = target
    weights, scales, lower, upper, rates = rules
    damping, progress, settled, steps = rates[0], rates[1], rates[2], int(rates[3])
    joints, nq = len(chain[0]), len(q)
    q = q.copy()
    work = (np.empty((joints, 3, 3)), np.empty((joints, 3)), np.empty((4, 3)))
    tool_rot, tool_pos, relative = np.empty((3, 3)), np.empty(3), np.empty((3, 3))
    jacobian, error, turn = np.zeros((6, nq)), np.empty(6), np.empty(3)
    solve_work, change, free = (np.empty((6, 6)), np.empty(6)), np.empty(nq), np.ones(nq, dtype=np.bool_)
    excess = np.inf
    for _ in range(steps):
        place_tool(q, chain, tool, work, tool_rot, tool_pos)
        rotation_error(tool_rot, rotation, relative, turn)
        for r in range(3):
            error[r] = (position[r] - tool_pos[r]) * weights[r]
            error[3 + r] = turn[r] * weights[3 + r]
        size = max(
            math.sqrt(error[0] ** 2 + error[1] ** 2 + error[2] ** 2),
            math.sqrt(error[3] ** 2 + error[4] ** 2 + error[5] ** 2),
        )
        if size > (1.0 - progress) * excess:  # settled: the least-squares pose, not the line's
            break
        excess = size
        if excess <= settled:
            break
        tool_jacobian(chain, tool, free, work, tool_pos, jacobian)
        lam = weighted_damping(jacobian, weights, damping)
        scale_columns(jacobian, scales)
        damped_step(jacobian, error, 6, lam, solve_work, change)
        scale_step(change, scales)
        for v in range(nq):
            q[v] = min(upper[v], max(lower[v], q[v] + change[v]))
    return q, excess
