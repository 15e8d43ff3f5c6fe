"""Damped least-squares steps on a tool frame's Jacobian, compiled: what every descent on it solves.

The step ``J^T (J J^T + lambda^2 I)^-1 e`` by a Cholesky factorisation of the small system
(:func:`damped_solve`, :func:`damped_step`), its damping as a share of the Jacobian's size where
its rows are weighted by tolerances (:func:`weighted_damping`), and the same step in the
coordinates ``q / scales`` (:func:`scale_columns`, :func:`scale_step`): with each joint's speed
scale, the step least in time rather than in the joints' own units. The Jacobians are
:func:`~cpr_kin.kinematics.tool_chain.tool_jacobian`'s.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit_inline

FloatArray = NDArray[np.float64]


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


@njit_inline
def damped_step(
    jacobian: FloatArray,
    error: FloatArray,
    rows: int,
    damping: float,
    work: tuple[FloatArray, FloatArray],
    out: FloatArray,
) -> None:
    """Write the damped least-squares step ``J^T (J J^T + damping^2 I)^-1 e`` into ``out`` ``(nq,)``.

    Of the first ``rows`` rows of ``jacobian`` ``(6, nq)`` and ``error`` ``(6,)``; ``work`` is
    ``(system (6, 6), solved (6,))``, scratch.
    """
    system, solved = work
    nq = jacobian.shape[1]
    for r in range(rows):
        for c in range(r + 1):
            total = damping * damping if r == c else 0.0
            for v in range(nq):
                total += jacobian[r, v] * jacobian[c, v]
            system[r, c] = total
            system[c, r] = total
    damped_solve(system, error, rows, solved)
    for v in range(nq):
        total = 0.0
        for r in range(rows):
            total += jacobian[r, v] * solved[r]
        out[v] = total


@njit_inline
def weighted_damping(jacobian: FloatArray, weights: FloatArray, share: float) -> float:
    """Scale the rows of ``jacobian`` ``(6, nq)`` by ``weights`` ``(6,)`` in place; its damping.

    The damping of a least-squares step on it: ``share * sqrt(max(trace(J J^T), 1))``, the
    share of the weighted Jacobian's size.
    """
    trace = 0.0
    for r in range(6):
        for v in range(jacobian.shape[1]):
            jacobian[r, v] *= weights[r]
            trace += jacobian[r, v] * jacobian[r, v]
    return share * math.sqrt(max(trace, 1.0))


@njit_inline
def scale_columns(jacobian: FloatArray, scales: FloatArray) -> None:
    """Scale each column ``v`` of ``jacobian`` ``(6, nq)`` by ``scales[v]`` in place.

    With :meth:`~cpr_kin.model.limits.JointLimits.speed_scales`, the Jacobian in coordinates
    ``z = q / scales``: a least-squares step there, scaled back by :func:`scale_step`, is the
    least in time (each joint's move over its speed) rather than in the joints' own units.
    """
    for r in range(jacobian.shape[0]):
        for v in range(jacobian.shape[1]):
            jacobian[r, v] *= scales[v]


@njit_inline
def scale_step(step: FloatArray, scales: FloatArray) -> None:
    """Scale a step ``(nq,)`` of :func:`scale_columns`' coordinates back to the joints' in place."""
    for v in range(len(step)):
        step[v] *= scales[v]
