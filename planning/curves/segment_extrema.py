"""Where the extrema of many polynomial segments may lie: the ends, and the slope's roots inside.

The exact extrema of a piecewise polynomial per joint lie at segment ends or at real roots of
its slope inside a segment. Finding roots (eigenvalues of companion matrices) costs far more
than evaluating the ends, and most segments cannot hold an extremum anyway: a segment whose
values all stay within the joint's extremes over every segment end adds nothing. Its values
stay within the convex hull of its Bernstein coefficients
(:mod:`planning.curves.polynomial_bounds`), so only the segments whose hull reaches the ends'
extremes are searched for roots. The extrema found are those of a search of every segment.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planning.curves.polynomial_bounds import bernstein_matrix

FloatArray = NDArray[np.float64]

REACH_TOLERANCE = 1e-12
"""Relative to the joint's largest |end value|: a hull this close to an extreme is searched too."""


def extremum_candidates(value: FloatArray, slope: FloatArray, h: FloatArray, joints: int) -> FloatArray:
    """Local times [s] at which each segment's extremum may lie, ``(rows, order + 1)``.

    Args:
        value: ``(rows, order)`` power coefficients of the polynomials in local time, the rows
            ordered segment by segment, ``joints`` per segment.
        slope: ``(rows, order)`` power coefficients of their derivatives.
        h: ``(rows,)`` the segments' durations [s].
        joints: polynomials per segment.

    Returns:
        Per row: ``0``, ``h``, then the slope's real roots inside ``(0, h)`` where the row's
        hull reaches its joint's extremes over the ends, ``nan`` in the other places.
    """
    rows, order = value.shape
    hull = (value * h[:, None] ** np.arange(order)) @ bernstein_matrix(order, 1.0).T
    per_joint = hull[:, [0, -1]].reshape(-1, joints, 2)  # b_0 = p(0), b_n = p(h)
    highest, lowest = per_joint.max(axis=(0, 2)), per_joint.min(axis=(0, 2))
    tolerance = REACH_TOLERANCE * np.maximum(np.abs(highest), np.abs(lowest))
    joint = np.arange(rows) % joints
    reaches = (hull.max(axis=1) >= (highest - tolerance)[joint]) | (
        hull.min(axis=1) <= (lowest + tolerance)[joint]
    )
    roots = np.full((rows, order - 1), np.nan)
    searched = np.flatnonzero(reaches)
    if searched.size:
        roots[searched] = real_roots_in(slope[searched], h[searched])
    return np.concatenate([np.zeros((rows, 1)), h[:, None], roots], axis=1)


def real_roots_in(coefficients: FloatArray, upper: FloatArray) -> FloatArray:
    """Real roots in ``(0, upper)`` of each polynomial ``sum_k c[m, k] x^k``, ``(M, order - 1)``.

    Each row holds its polynomial's roots, ``nan`` in the places of the others. Polynomials
    are grouped by their effective degree (leading coefficients below a relative tolerance
    are dropped) and the eigenvalues of their companion matrices computed in stacks, so many
    small polynomials cost few NumPy calls and no Python loop over them.
    """
    m_count, order = coefficients.shape
    roots = np.full((m_count, order - 1), np.nan)
    scale = np.abs(coefficients).max(axis=1, keepdims=True)
    significant = np.abs(coefficients) > 1e-13 * np.where(scale > 0, scale, 1.0)
    degree = np.where(significant.any(axis=1), order - 1 - np.argmax(significant[:, ::-1], axis=1), 0)
    for d in range(1, order):
        rows = np.flatnonzero(degree == d)
        if rows.size == 0:
            continue
        c = coefficients[rows, : d + 1]
        companion = np.zeros((rows.size, d, d))
        companion[:, 1:, :-1] = np.eye(d - 1)
        companion[:, :, -1] = -c[:, :d] / c[:, d : d + 1]
        z = np.linalg.eigvals(companion)
        real = np.abs(z.imag) <= 1e-9 * (1.0 + np.abs(z.real))
        inside = real & (z.real > 0.0) & (z.real < upper[rows, None])
        roots[rows, :d] = np.where(inside, z.real, np.nan)
    return roots
