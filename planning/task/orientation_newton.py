"""The projection onto an orientation constraint, compiled: one configuration turned back onto it.

:mod:`planning.task.orientation_projection` moves a configuration the least onto the manifold
of an orientation constraint by Newton's method with damped least squares; a constrained
motion projects thousands of them (its bent path's samples, its RRT's extensions). In Python
each step is a Pinocchio Jacobian and a small solve, tens of microseconds of calls for
microseconds of arithmetic; here a projection runs compiled on the robot's chain to the frame
(:mod:`cpr_kin.kinematics.tool_chain`), by the rules of that module.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays
from cpr_kin.common.compiled import njit, njit_inline
from cpr_kin.kinematics.least_squares import damped_step
from cpr_kin.kinematics.tool_chain import ToolArrays, place_tool, rotation_error, tool_jacobian

FloatArray = NDArray[np.float64]
ProjectionRules = tuple[FloatArray, FloatArray, FloatArray, FloatArray]
"""How a projection steps and stops: ``weights`` ``(6,)`` (position, then angle), ``lower`` and
``upper`` ``(nq,)`` [rad, m], and ``[aim, free axis, keep position, damping, steps]`` (the free
axis 0, 1, 2 or -1 for none; keep position 1 or 0)."""


@njit_inline
def constraint_error(
    tool_rot: FloatArray, reference: FloatArray, free: int, relative: FloatArray, out: FloatArray
) -> float:
    """Write the least world-aligned rotation onto the constraint into ``out`` ``(3,)`` [rad]; its angle.

    As :meth:`~planning.task.orientation.OrientationConstraint.error`: with a free axis, the
    rotation taking that axis of ``tool_rot`` onto the reference's; without one, the rotation
    to ``reference``. ``relative`` ``(3, 3)`` is scratch.
    """
    if free < 0:
        rotation_error(tool_rot, reference, relative, out)
    else:
        a0, a1, a2 = tool_rot[0, free], tool_rot[1, free], tool_rot[2, free]
        b0, b1, b2 = reference[0, free], reference[1, free], reference[2, free]
        n0, n1, n2 = a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0
        sine = math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)
        if sine < 1e-15:
            out[0], out[1], out[2] = 0.0, 0.0, 0.0
        else:
            scale = math.atan2(sine, a0 * b0 + a1 * b1 + a2 * b2) / sine
            out[0], out[1], out[2] = n0 * scale, n1 * scale, n2 * scale
    return math.sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2])


@njit
def project_on_constraint(
    q: FloatArray, chain: ChainArrays, tool: ToolArrays, reference: FloatArray, rules: ProjectionRules
) -> tuple[FloatArray, float]:
    """``q`` ``(nq,)`` turned back to the constraint's aim, and its angle there [rad].

    Each step measures the constraint's error at the frame; once its angle is at most
    ``aim`` (or after ``steps`` steps) it stops; otherwise it asks for a turn that leaves
    ``0.9 aim`` of the angle and, with ``keep position``, the frame's origin where it was at
    the start, both times ``weights``, and moves by the damped least-squares step of the
    weighted Jacobian (its angular rows less the turn about the free axis),
    ``lambda = damping * sqrt(max(trace(J J^T), 1))``, into ``[lower, upper]``.
    """
    weights, lower, upper, rates = rules
    aim, free, keep, damping, steps = rates[0], int(rates[1]), rates[2] > 0.0, rates[3], int(rates[4])
    joints, nq = len(chain[0]), len(q)
    q = q.copy()
    work = (np.empty((joints, 3, 3)), np.empty((joints, 3)), np.empty((4, 3)))
    tool_rot, tool_pos, where, relative = np.empty((3, 3)), np.empty(3), np.empty(3), np.empty((3, 3))
    full, weighted, error, turn = np.zeros((6, nq)), np.zeros((6, nq)), np.empty(6), np.empty(3)
    solve_work, change, moving = (np.empty((6, 6)), np.empty(6)), np.empty(nq), np.ones(nq, dtype=np.bool_)
    first = 3 if keep else 0  # where the angular rows go in the weighted system
    angle = math.inf
    for step in range(steps + 1):
        place_tool(q, chain, tool, work, tool_rot, tool_pos)
        if step == 0:
            where[:] = tool_pos
        angle = constraint_error(tool_rot, reference, free, relative, turn)
        if angle <= aim or step == steps:
            break
        shrink = 1.0 - 0.9 * aim / angle
        tool_jacobian(chain, tool, moving, work, tool_pos, full)
        if free >= 0:  # less the turn about the free axis: (I - a a^T) J_angular
            a0, a1, a2 = tool_rot[0, free], tool_rot[1, free], tool_rot[2, free]
            for v in range(nq):
                along = a0 * full[3, v] + a1 * full[4, v] + a2 * full[5, v]
                full[3, v] -= a0 * along
                full[4, v] -= a1 * along
                full[5, v] -= a2 * along
        trace = 0.0
        for r in range(3):
            if keep:
                error[r] = (where[r] - tool_pos[r]) * weights[r]
            error[first + r] = turn[r] * shrink * weights[3 + r]
            for v in range(nq):
                if keep:
                    weighted[r, v] = full[r, v] * weights[r]
                    trace += weighted[r, v] * weighted[r, v]
                weighted[first + r, v] = full[3 + r, v] * weights[3 + r]
                trace += weighted[first + r, v] * weighted[first + r, v]
        damped_step(weighted, error, first + 3, damping * math.sqrt(max(trace, 1.0)), solve_work, change)
        for v in range(nq):
            q[v] = min(upper[v], max(lower[v], q[v] + change[v]))
    return q, angle


@njit
def project_steps(
    q: FloatArray,
    aim: FloatArray,
    chain: ChainArrays,
    tool: ToolArrays,
    reference: FloatArray,
    rules: ProjectionRules,
    walk: FloatArray,
) -> tuple[FloatArray, int, bool, float]:
    """Up to ``count`` projected steps from ``q`` toward ``aim`` (both ``(nq,)``), and whether it got stuck.

    ``walk`` is ``[step, range left, count, radii (nq)]`` (:mod:`planning.task.orientation_rrt`):
    each step aims ``step`` [m] of robot motion (``sum_j radii_j |dq_j|``) along the straight
    line to ``aim`` (at ``aim`` itself once it is that close) and is projected onto the
    manifold; the walk is stuck where a projection does not get there, jumps more than twice a
    step, or comes no closer to ``aim``. It stops after ``count`` steps, at ``aim``, or once it
    has travelled the range left. Returns the steps ``(count, nq)`` (the first ``n`` are
    walked), ``n``, whether it got stuck and the robot motion travelled [m].
    """
    step_m, range_m, count = walk[0], walk[1], int(walk[2])
    radii = walk[3:]
    nq = len(q)
    steps = np.zeros((count, nq))
    guess = np.empty(nq)
    left, travelled, n = _distance(q, aim, radii), 0.0, 0
    while n < count and left > 1e-9 and travelled < range_m:
        for v in range(nq):
            guess[v] = aim[v] if left <= step_m else q[v] + (aim[v] - q[v]) * (step_m / left)
        stepped, angle = project_on_constraint(guess, chain, tool, reference, rules)
        moved, remaining = _distance(q, stepped, radii), _distance(stepped, aim, radii)
        if angle > rules[3][0] or moved > 2.0 * step_m or remaining >= left:
            return steps, n, True, travelled
        steps[n] = stepped
        q, left, travelled, n = stepped, remaining, travelled + moved, n + 1
    return steps, n, False, travelled


@njit_inline
def _distance(a: FloatArray, b: FloatArray, radii: FloatArray) -> float:
    """The robot motion between ``a`` and ``b``, ``sum_j radii_j |a_j - b_j|`` [m]."""
    total = 0.0
    for v in range(len(a)):
        total += radii[v] * abs(a[v] - b[v])
    return total
