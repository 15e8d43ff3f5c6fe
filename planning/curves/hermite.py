"""Degree-7 Hermite segments (paper eq. 14) and their derivative energies.

A segment on the normalised interval ``tau in [0, 1]`` is ``x(tau) = sum_k a_k tau^k``,
``k = 0..7``. Its *Hermite data* are ``c = (x, x', x'', x''')`` at ``tau = 0`` followed by
the same at ``tau = 1``: ``c = HERMITE @ a``. (The paper's eq. 14 lists the same eight
equations interleaved.)

``ENERGY[r]`` maps Hermite data to the integral of the squared ``r``-th derivative,
``int_0^1 (x^(r))^2 dtau = c @ ENERGY[r] @ c``.
"""

from __future__ import annotations

from math import factorial

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

DEGREE = 7
ORDER = DEGREE + 1  # coefficients per segment
CONTINUITY = 3  # derivatives continuous at the knots (y, y', y'', y''')


def _falling(k: int, r: int) -> int:
    """``k! / (k - r)!``: the factor of ``tau^(k-r)`` in the ``r``-th derivative of ``tau^k``."""
    return factorial(k) // factorial(k - r) if k >= r else 0


def derivative_matrix(r: int, order: int = ORDER) -> FloatArray:
    """``(order, order)`` matrix ``M`` with ``a^(r) = M @ a``: power coefficients of the r-th derivative."""
    m = np.zeros((order, order))
    for k in range(r, order):
        m[k - r, k] = _falling(k, r)
    return m


def _hermite() -> FloatArray:
    h = np.zeros((ORDER, ORDER))
    for r in range(CONTINUITY + 1):
        h[r, r] = factorial(r)  # x^(r)(0)
        for k in range(ORDER):
            h[CONTINUITY + 1 + r, k] = _falling(k, r)  # x^(r)(1)
    return h


def gram(r: int) -> FloatArray:
    """``(8, 8)`` Gram matrix ``Q[k, l] = int_0^1 d^r(tau^k) d^r(tau^l) dtau``."""
    q = np.zeros((ORDER, ORDER))
    for k in range(r, ORDER):
        for m in range(r, ORDER):
            q[k, m] = _falling(k, r) * _falling(m, r) / (k + m - 2 * r + 1)
    return q


HERMITE = _hermite()
"""Power coefficients -> Hermite data ``(x, x', x'', x''')`` at 0 then at 1."""

HERMITE_INV = np.linalg.inv(HERMITE)
"""Hermite data -> power coefficients."""

ENERGY = {r: HERMITE_INV.T @ gram(r) @ HERMITE_INV for r in range(1, CONTINUITY + 2)}
"""Hermite data -> integral of the squared r-th derivative over [0, 1], r = 1..4."""


_NODE_POWERS = np.tile(np.arange(CONTINUITY + 1, dtype=float), 2)


def node_scaling(h: FloatArray) -> FloatArray:
    """``(..., 8)`` factors ``h^r`` turning physical node derivatives into tau-derivatives."""
    return np.asarray(h[..., None] ** _NODE_POWERS)
