"""Many piecewise polynomials evaluated at the same fixed times, with their derivatives.

The fitness evaluates every joint of every candidate path (a few hundred columns) at the
same times over and over. Precomputing, per segment, the matrix of (derivative) powers of
the local times turns each evaluation into one matrix product per segment and order. The
results go into buffers kept between calls: for arrays of this size (a few hundred kB) a
fresh allocation costs more in page faults than the products themselves. The matrices depend
only on the knots and times, which every problem of a planner's settings shares (the search's
knots are the waypoints' indices): they are computed once for each (:func:`_blocks`).
"""

from __future__ import annotations

import functools

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.arrays import distinct_sorted
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]


def derivative_powers(local_s: FloatArray, order: int, derivative: int) -> FloatArray:
    """``(T, order)`` matrix ``P`` with ``P @ c`` the ``derivative``-th derivative of ``sum_k c_k t^k``.

    ``P[t, k] = k! / (k - r)! t^(k - r)`` for ``k >= r`` and 0 below, at local times
    ``local_s`` [s].
    """
    k = np.arange(order)
    factor = np.ones(order)
    for m in range(derivative):
        factor = factor * (k - m)
    exponent = np.maximum(k - derivative, 0)
    return np.asarray(factor * local_s[:, None] ** exponent)


class PiecewiseSampler:
    """Evaluates piecewise polynomials and their first derivatives at fixed times.

    Args:
        knots: ``(N + 1,)`` increasing segment boundaries [s].
        times: ``(K,)`` non-decreasing evaluation times [s] within the knots.
        order: number of power coefficients per segment (8 for septic).
        derivatives: highest derivative order evaluated.
        first: lowest derivative order evaluated (0: the values).

    Calling it with coefficients ``(N, M, order)`` (``M`` columns, e.g. every joint of every
    candidate) returns ``(derivatives - first + 1, K, M)``: derivative orders ``first`` to
    ``derivatives``. The array is the sampler's own buffer, overwritten by its next call:
    copy what must outlive it.
    """

    def __init__(
        self, knots: ArrayLike, times: ArrayLike, order: int, derivatives: int = 0, first: int = 0
    ) -> None:
        knots = np.asarray(knots, dtype=float)
        times = np.asarray(times, dtype=float)
        if knots.ndim != 1 or len(knots) < 2 or not (np.diff(knots) > 0).all():
            raise PlanningError(f"knots {knots.tolist()} must be at least two increasing times [s]")
        if times.ndim != 1 or times.size == 0 or (np.diff(times) < 0).any():
            raise PlanningError("sample times must be a non-empty, non-decreasing 1-D array [s]")
        if times[0] < knots[0] or times[-1] > knots[-1]:
            raise PlanningError(
                f"sample times [{times[0]}, {times[-1]}] s leave the knots [{knots[0]}, {knots[-1]}] s"
            )
        if not 0 <= derivatives < order:
            raise PlanningError(f"derivatives = {derivatives} must lie in [0, {order - 1}]")
        if not 0 <= first <= derivatives:
            raise PlanningError(f"first = {first} must lie in [0, derivatives = {derivatives}]")
        self.order = order
        self.derivatives = derivatives
        self.first = first
        self.count = len(times)
        self._blocks = _blocks(tuple(knots.tolist()), tuple(times.tolist()), order, derivatives, first)
        self._buffer = np.empty(0)  # grows to the largest call's size, reused below it

    def __call__(self, coefficients: FloatArray) -> FloatArray:
        """``(derivatives - first + 1, K, M)`` derivatives of ``(N, M, order)`` coefficients."""
        shape = (self.derivatives - self.first + 1, self.count, coefficients.shape[1])
        size = shape[0] * shape[1] * shape[2]
        if self._buffer.size < size:
            self._buffer = np.empty(size)
        out = self._buffer[:size].reshape(shape)
        for segment, rows, powers in self._blocks:
            columns = coefficients[segment].T  # (order, M)
            for r, matrix in enumerate(powers):
                np.matmul(matrix, columns, out=out[r, rows])
        return out


Block = tuple[int, slice, tuple[FloatArray, ...]]
"""A segment, the rows of its times, and its matrices of :func:`derivative_powers` (read-only)."""


@functools.lru_cache(maxsize=64)
def _blocks(
    knots: tuple[float, ...], times: tuple[float, ...], order: int, derivatives: int, first: int
) -> tuple[Block, ...]:
    """Per segment holding some of ``times``: its rows and power matrices (:class:`PiecewiseSampler`)."""
    knots_s, times_s = np.asarray(knots), np.asarray(times)
    segment = np.clip(np.searchsorted(knots_s, times_s, side="right") - 1, 0, len(knots_s) - 2)
    local = times_s - knots_s[segment]
    blocks = []
    for i in distinct_sorted(segment):
        rows = np.flatnonzero(segment == i)  # contiguous: the times are sorted
        powers = tuple(derivative_powers(local[rows], order, r) for r in range(first, derivatives + 1))
        for matrix in powers:
            matrix.setflags(write=False)  # shared by every sampler of these times
        blocks.append((int(i), slice(int(rows[0]), int(rows[-1]) + 1), powers))
    return tuple(blocks)
