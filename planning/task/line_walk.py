"""A tool line's walk, compiled: each sample predicted along the line's twist, then put on its pose.

:mod:`planning.task.line_ik` walks a line in hundreds of small steps. Each step predicts the
joints by the damped pseudo-inverse of the tolerance-weighted Jacobian applied to the line's
twist over the step, the step least in time (the Jacobian's columns scaled by the joints'
speed scales: on a redundant arm the fast joints move, a slow torso lift hardly; on
others the same step), on a redundant arm plus a pull of joints near a limit toward the
middle of their range, in the Jacobian's null space; then corrects them onto the line's pose there
(:func:`~planning.task.line_newton.newton_to_pose`). A sample that stays too far from the line
or makes a joint jump ends the walk; the caller says why. The rules are those of
:mod:`planning.task.line_ik` and :mod:`planning.task.joint_ranges`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.bounds.batch_kinematics import ChainArrays
from cpr_kin.common.compiled import njit, njit_inline
from cpr_kin.kinematics.least_squares import damped_step, scale_columns, scale_step, weighted_damping
from cpr_kin.kinematics.tool_chain import ToolArrays, place_tool, tool_jacobian
from planning.task.line_newton import NewtonRules, newton_to_pose

FloatArray = NDArray[np.float64]
LinePoses = tuple[FloatArray, FloatArray, FloatArray]
"""The line at the walk's samples: ``sigma`` ``(K,)``, positions ``(K, 3)`` [m] and rotations
``(K, 3, 3)`` in the world."""
WalkRules = tuple[FloatArray, FloatArray, FloatArray]
"""How the walk predicts and when it stops: the line's weighted twist ``(6,)`` (per unit of
``sigma``), the joint ranges the pull measures from, ``(2, nq)`` [rad, m], and ``[pull gain,
limit zone, reach share, largest joint step]``."""


@njit
def walk_line(
    q: FloatArray, chain: ChainArrays, tool: ToolArrays, line: LinePoses, newton: NewtonRules, walk: WalkRules
) -> tuple[FloatArray, float, int, FloatArray, float]:
    """The walk's samples from ``q`` ``(nq,)`` at the line's ``sigma``, and where it broke.

    Returns ``(samples (K, nq), residual, broken, found, excess)``: the samples, the largest
    corrector error (over the tolerance) of those kept; ``broken`` the index of the sample that
    ended the walk (its error ``excess`` above the reach share, or a joint of ``found`` more
    than the largest step from the sample before), ``-1`` where the walk reached the end
    (``samples`` is then whole; otherwise only its first ``broken`` rows are the walk's).
    """
    sigma, positions, rotations = line
    weights, scales, lower, upper, rates = newton
    twist, ranges, checks = walk
    gain, zone, reach_share, largest_step = checks[0], checks[1], checks[2], checks[3]
    damping = rates[0]
    joints, nq = len(chain[0]), len(q)
    samples = np.zeros((len(sigma), nq))
    samples[0] = q
    q = q.copy()
    work = (np.empty((joints, 3, 3)), np.empty((joints, 3)), np.empty((4, 3)))
    tool_rot, tool_pos = np.empty((3, 3)), np.empty(3)
    jacobian, change, rhs = np.zeros((6, nq)), np.empty(6), np.empty(6)
    solve_work, step, back = (np.empty((6, 6)), np.empty(6)), np.empty(nq), np.empty(nq)
    pull, free = np.empty(nq), np.ones(nq, dtype=np.bool_)
    residual = 0.0
    for k in range(1, len(sigma)):
        place_tool(q, chain, tool, work, tool_rot, tool_pos)
        tool_jacobian(chain, tool, free, work, tool_pos, jacobian)
        lam = weighted_damping(jacobian, weights, damping)
        progress = sigma[k] - sigma[k - 1]
        for r in range(6):
            change[r] = twist[r] * progress
        pulled = gain > 0.0 and _limit_pull(q, ranges, zone, pull)
        if pulled:
            for r in range(6):  # what the Jacobian sees of the pull (in the joints' own units)
                total = 0.0
                for v in range(nq):
                    total += jacobian[r, v] * pull[v]
                rhs[r] = total
        scale_columns(jacobian, scales)
        damped_step(jacobian, change, 6, lam, solve_work, step)
        scale_step(step, scales)
        if pulled:  # the pull less what the Jacobian sees of it: its null-space part
            damped_step(jacobian, rhs, 6, lam, solve_work, back)
            scale_step(back, scales)
            for v in range(nq):
                step[v] += gain * (pull[v] - back[v])
        for v in range(nq):
            step[v] = min(upper[v], max(lower[v], q[v] + step[v]))
        found, excess = newton_to_pose(step, chain, tool, (positions[k], rotations[k]), newton)
        jump = 0.0
        for v in range(nq):
            jump = max(jump, abs(found[v] - q[v]))
        if excess > reach_share or jump > largest_step:
            return samples, residual, k, found, excess
        q = found
        residual = max(residual, excess)
        samples[k] = q
    return samples, residual, -1, q, 0.0


@njit_inline
def _limit_pull(q: FloatArray, ranges: FloatArray, zone: float, out: FloatArray) -> bool:
    """Write the pull of each joint from its limits, ``depth * (middle - q)``, into ``out``.

    ``depth`` is 0 in the inner ``1 - zone`` of each joint's ``ranges`` ``(2, nq)``, rising to 1
    at its ends (0 for a joint of no range; :mod:`planning.task.joint_ranges`). Whether any
    joint is that deep.
    """
    deep = False
    for v in range(len(q)):
        middle, half = 0.5 * (ranges[0, v] + ranges[1, v]), 0.5 * (ranges[1, v] - ranges[0, v])
        depth = 0.0 if half <= 0.0 else min(1.0, max(0.0, (abs(q[v] - middle) / half - (1.0 - zone)) / zone))
        out[v] = depth * (middle - q[v])
        deep = deep or depth > 0.0
    return deep
