"""Cholesky factorisation and solves of symmetric positive definite band matrices, compiled.

LAPACK's ``dpbtrf`` and ``dpbtrs`` in lower band storage (``band[i - j, j] = A[i, j]`` for
``j <= i <= j + kd``), written out so that planning needs no ``scipy.linalg``: importing it
costs a new process 0.25-0.3 s, a sixth of ``cpr-plan plan``'s wall time, for two routines
of twenty lines. Checked against SciPy's ``cholesky_banded`` and ``cho_solve_banded``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit

FloatArray = NDArray[np.float64]


@njit
def band_cholesky(band: FloatArray) -> tuple[FloatArray, int]:
    """The lower band Cholesky factor of ``band`` ``(kd + 1, n)``, and LAPACK's ``info``.

    ``info`` is 0 on success, else ``k + 1`` where the leading minor of order ``k + 1`` is
    not positive definite (the factor is then incomplete).
    """
    kd1, n = band.shape
    kd = kd1 - 1
    factor = band.copy()
    for j in range(n):
        # the diagonal: A[j, j] - sum_k L[j, k]^2 over the band
        pivot = factor[0, j]
        for k in range(max(0, j - kd), j):
            value = factor[j - k, k]
            pivot -= value * value
        if not pivot > 0.0:
            return factor, j + 1
        root = math.sqrt(pivot)
        factor[0, j] = root
        for i in range(j + 1, min(n, j + kd1)):
            total = factor[i - j, j]
            for k in range(max(0, i - kd), j):
                total -= factor[i - k, k] * factor[j - k, k]
            factor[i - j, j] = total / root
    return factor, 0


@njit
def band_cholesky_solve(factor: FloatArray, rhs: FloatArray) -> FloatArray:
    """``x`` with ``L L^T x = rhs`` ``(n, m)`` for the lower band factor ``L`` ``(kd + 1, n)``."""
    kd1, n = factor.shape
    x = rhs.copy()
    m = x.shape[1]
    for j in range(n):  # forward: L y = rhs
        for k in range(max(0, j - kd1 + 1), j):
            coefficient = factor[j - k, k]
            for c in range(m):
                x[j, c] -= coefficient * x[k, c]
        for c in range(m):
            x[j, c] /= factor[0, j]
    for j in range(n - 1, -1, -1):  # backward: L^T x = y
        for i in range(j + 1, min(n, j + kd1)):
            coefficient = factor[i - j, j]
            for c in range(m):
                x[j, c] -= coefficient * x[i, c]
        for c in range(m):
            x[j, c] /= factor[0, j]
    return x
