"""Certified upper bounds on |derivatives| of piecewise polynomials (Bernstein hull).

On a segment ``[0, h]`` a polynomial of degree ``n`` in power form, ``p(t) = sum_k c_k t^k``,
is also ``p(t) = sum_i b_i B_i(t / h)`` in the Bernstein basis of degree ``n``, with

    b_i = sum_{k <= i} C(i, k) / C(n, k) h^k c_k.

The Bernstein basis functions are non-negative and sum to one, so ``p`` stays within the
convex hull of its coefficients: ``max |p| <= max_i |b_i|``, with equality whenever the
largest |value| is at an end of the segment (``b_0 = p(0)``, ``b_n = p(h)``). A derivative
of order ``r`` is bounded the same way, as a degree-``n`` polynomial (its degree elevation,
whose hull is no wider than that of its own degree).

The fitness uses the bound to tell, at the cost of one small product per segment, which
joints certainly stay within their velocity, acceleration and jerk limits; only the others
are sampled densely.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from math import comb

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planning.curves.hermite import derivative_matrix
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]


def bernstein_matrix(order: int, h: float) -> FloatArray:
    """``(order, order)`` matrix ``B`` with ``B @ c`` the Bernstein coefficients on ``[0, h]``.

    ``c`` are the power coefficients of a polynomial of degree ``order - 1`` in local time
    ``t`` [s]; the result are its Bernstein coefficients of that degree in ``t / h``.
    """
    n = order - 1
    matrix = np.zeros((order, order))
    for i in range(order):
        for k in range(i + 1):
            matrix[i, k] = comb(i, k) / comb(n, k) * h**k
    return matrix


class DerivativeBounds:
    """Upper bounds of ``max_t |q^(r)(t)|`` over whole piecewise polynomials, per column.

    Args:
        knots: ``(N + 1,)`` increasing segment boundaries [s].
        order: power coefficients per segment (8 for septic).
        derivatives: the derivative orders ``r`` to bound (e.g. ``(1, 2, 3)``).

    Calling it with coefficients ``(N, M, order)`` (local time per segment, the layout of
    :class:`~planning.curves.trajectory.Trajectory`) returns ``(len(derivatives), M)`` bounds, each
    at least the true largest |value| of that derivative over all segments.
    """

    def __init__(self, knots: ArrayLike, order: int, derivatives: Sequence[int]) -> None:
        knots = np.asarray(knots, dtype=float)
        if knots.ndim != 1 or len(knots) < 2 or not (np.diff(knots) > 0).all():
            raise PlanningError(f"knots {knots.tolist()} must be at least two increasing times [s]")
        if not derivatives or not all(0 <= r < order for r in derivatives):
            raise PlanningError(f"derivatives {list(derivatives)} must be orders in [0, {order - 1}]")
        self.order = order
        self.derivatives = tuple(int(r) for r in derivatives)
        self._matrices = _hull_matrices(tuple(np.diff(knots).tolist()), order, self.derivatives)

    def __call__(self, coefficients: FloatArray) -> FloatArray:
        """``(len(derivatives), M)`` bounds for ``(N, M, order)`` coefficients."""
        n = len(self._matrices)
        if coefficients.ndim != 3 or coefficients.shape[0] != n or coefficients.shape[2] != self.order:
            expected = f"({n}, M, {self.order})"
            raise PlanningError(f"coefficients of shape {coefficients.shape}; expected {expected}")
        # columns last, so that the largest |coefficient| is taken across contiguous rows
        hull = np.abs(np.matmul(self._matrices, coefficients.transpose(0, 2, 1)))
        return np.asarray(hull.reshape(n, len(self.derivatives), self.order, -1).max(axis=(0, 2)))


@functools.lru_cache(maxsize=64)
def _hull_matrices(steps_s: tuple[float, ...], order: int, derivatives: tuple[int, ...]) -> FloatArray:
    """``(N, R order, order)`` Bernstein matrices of every derivative, per segment of ``steps_s`` [s].

    :class:`DerivativeBounds`' one product per segment; read-only, shared by equal knots.
    """
    matrices = np.stack(
        [
            np.vstack([bernstein_matrix(order, h) @ derivative_matrix(r, order) for r in derivatives])
            for h in steps_s
        ]
    )
    matrices.setflags(write=False)
    return matrices
