"""The interpolating B-spline of odd degree, compiled: collocation, its banded solve, the pieces.

What :func:`scipy.interpolate.make_interp_spline` computes for an odd degree ``k`` and no end
conditions (de Boor's not-a-knot knots: ``k + 1`` at each end, the data sites between but the
``(k - 1) / 2`` next to each end), written out so that planning needs no
``scipy.interpolate``: importing it costs a new process 0.2 s, for a collocation of twenty
lines. The collocation matrix is banded and totally positive, so Gaussian elimination without
pivoting is stable (de Boor, *A Practical Guide to Splines*, XIII); the basis functions and
their derivatives are Piegl and Tiller's (*The NURBS Book*, A2.2 and A2.3). Checked against
scipy (tests/test_interpolating_spline.py).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from cpr_kin.common.compiled import njit, njit_inline

FloatArray = NDArray[np.float64]
BasisWork = tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray]
"""Scratch of :func:`basis_derivatives`: ``ndu``, ``left``, ``right``, ``a``, ``ders``."""


@njit_inline
def knot_span(knots: FloatArray, degree: int, n_basis: int, x: float) -> int:
    """The span ``l`` of ``x``: ``knots[l] <= x < knots[l + 1]``, ``degree <= l < n_basis``.

    At the last knot, the last span.
    """
    low, high = degree, n_basis
    if x >= knots[n_basis]:
        return n_basis - 1
    while high - low > 1:  # knots[low] <= x < knots[high]
        middle = (low + high) // 2
        if x < knots[middle]:
            high = middle
        else:
            low = middle
    return low


@njit_inline
def basis_derivatives(
    knots: FloatArray, degree: int, span: int, x: float, count: int, work: BasisWork
) -> FloatArray:
    """``(count + 1, degree + 1)`` the derivatives 0..``count`` at ``x`` of the span's basis functions.

    Column ``j`` is the function ``span - degree + j`` (Piegl and Tiller's A2.3). ``work`` is
    :func:`basis_work`'s, written over (the view returned is its ``ders``).
    """
    ndu, left, right, a, ders = work
    p = degree
    ndu[0, 0] = 1.0
    for j in range(1, p + 1):
        left[j] = x - knots[span + 1 - j]
        right[j] = knots[span + j] - x
        saved = 0.0
        for r in range(j):
            ndu[j, r] = right[r + 1] + left[j - r]
            temp = ndu[r, j - 1] / ndu[j, r]
            ndu[r, j] = saved + right[r + 1] * temp
            saved = left[j - r] * temp
        ndu[j, j] = saved
    for j in range(p + 1):
        ders[0, j] = ndu[j, p]
    for r in range(p + 1):
        s1, s2 = 0, 1
        a[0, 0] = 1.0
        for k in range(1, count + 1):
            d = 0.0
            rk, pk = r - k, p - k
            if r >= k:
                a[s2, 0] = a[s1, 0] / ndu[pk + 1, rk]
                d = a[s2, 0] * ndu[rk, pk]
            j1 = 1 if rk >= -1 else -rk
            j2 = k - 1 if r - 1 <= pk else p - r
            for j in range(j1, j2 + 1):
                a[s2, j] = (a[s1, j] - a[s1, j - 1]) / ndu[pk + 1, rk + j]
                d += a[s2, j] * ndu[rk + j, pk]
            if r <= pk:
                a[s2, k] = -a[s1, k - 1] / ndu[pk + 1, r]
                d += a[s2, k] * ndu[r, pk]
            ders[k, r] = d
            s1, s2 = s2, s1
    factor = float(p)
    for k in range(1, count + 1):
        for j in range(p + 1):
            ders[k, j] *= factor
        factor *= p - k
    return ders


@njit_inline
def basis_work(degree: int) -> BasisWork:
    """Scratch arrays of :func:`basis_derivatives` for ``degree``, made once per spline."""
    size = degree + 1
    table, ders = np.zeros((size, size)), np.zeros((size, size))
    return table, np.zeros(size), np.zeros(size), np.zeros((2, size)), ders


@njit
def interpolating_coefficients(
    knots: FloatArray, degree: int, sites: FloatArray, values: FloatArray
) -> FloatArray:
    """``(n, m)`` the coefficients on ``knots`` of the spline through ``values`` ``(n, m)`` at ``sites``.

    The collocation matrix, in band storage ``band[i, j - i + degree]``, eliminated without
    pivoting (module docstring).
    """
    n, width = len(sites), 2 * degree + 1
    band = np.zeros((n, width))
    rhs = values.copy()
    work = basis_work(degree)
    for i in range(n):
        span = knot_span(knots, degree, n, sites[i])
        row = basis_derivatives(knots, degree, span, sites[i], 0, work)
        for j in range(degree + 1):
            band[i, span - degree + j - i + degree] = row[0, j]
    for col in range(n):  # forward elimination
        pivot = band[col, degree]
        for i in range(col + 1, min(n, col + degree + 1)):
            factor = band[i, col - i + degree] / pivot
            if factor == 0.0:
                continue
            for j in range(col, min(n, col + degree + 1)):
                band[i, j - i + degree] -= factor * band[col, j - col + degree]
            for c in range(rhs.shape[1]):
                rhs[i, c] -= factor * rhs[col, c]
    for row_index in range(n - 1, -1, -1):  # back substitution
        for j in range(row_index + 1, min(n, row_index + degree + 1)):
            coefficient = band[row_index, j - row_index + degree]
            for c in range(rhs.shape[1]):
                rhs[row_index, c] -= coefficient * rhs[j, c]
        pivot = band[row_index, degree]
        for c in range(rhs.shape[1]):
            rhs[row_index, c] /= pivot
    return rhs


@njit
def power_pieces(knots: FloatArray, degree: int, coefficients: FloatArray, order: int) -> FloatArray:
    """``(pieces, m, order)`` each piece's Taylor coefficients about its left knot, of the spline.

    The pieces are the spans of positive length between ``knots[degree]`` and ``knots[n]``,
    ``n`` the coefficients' count.
    """
    n, m = coefficients.shape
    count = 0
    for span in range(degree, n):
        if knots[span + 1] > knots[span]:
            count += 1
    out = np.zeros((count, m, order))
    work = basis_work(degree)
    piece = 0
    for span in range(degree, n):
        if not knots[span + 1] > knots[span]:
            continue
        ders = basis_derivatives(knots, degree, span, knots[span], degree, work)
        factorial = 1.0
        for r in range(degree + 1):
            if r > 0:
                factorial *= r
            for j in range(degree + 1):
                weight = ders[r, j] / factorial
                for c in range(m):
                    out[piece, c, r] += weight * coefficients[span - degree + j, c]
        piece += 1
    return out
