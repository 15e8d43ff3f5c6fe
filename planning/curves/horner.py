"""Piecewise polynomials evaluated by Horner's rule, compiled.

What :meth:`planning.curves.trajectory.Trajectory.__call__` runs: one pass over the times,
each placed in its segment by binary search, without the ``(K, nj, order)`` copy of the
coefficients NumPy's fancy indexing makes. Its own module so that reading a trajectory file
does not load the compiler (``tests/test_packages.py``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit

FloatArray = NDArray[np.float64]


@njit
def evaluate(coefficients: FloatArray, knots: FloatArray, times: FloatArray) -> FloatArray:
    """``(K, nj)`` the polynomials ``coefficients`` ``(N, nj, order)`` at ``times`` ``(K,)`` by Horner's rule.

    Each time in the segment ``i`` with ``knots[i] <= t < knots[i + 1]`` (the last segment
    from its start on, the first before its end), clamped to the knots.
    """
    segments, joints, order = coefficients.shape
    values = np.empty((len(times), joints))
    for m in range(len(times)):
        t = min(max(times[m], knots[0]), knots[-1])
        i = min(max(np.searchsorted(knots, t, side="right") - 1, 0), segments - 1)
        local = t - knots[i]
        for j in range(joints):
            value = coefficients[i, j, order - 1]
            for k in range(order - 2, -1, -1):
                value = value * local + coefficients[i, j, k]
            values[m, j] = value
    return values
