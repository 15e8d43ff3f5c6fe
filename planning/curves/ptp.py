"""Point-to-point timing: synchronised rest-to-rest trapezoidal moves (paper's t_sol)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def trapezoid_time(distance: ArrayLike, v_max: ArrayLike, a_max: ArrayLike) -> FloatArray:
    """Shortest rest-to-rest time [s] over ``|distance|`` under speed and acceleration limits.

    A trapezoidal profile when the cruise speed is reached (``|d| >= v^2 / a``):
    ``|d| / v + v / a``; a triangular one otherwise: ``2 sqrt(|d| / a)``. Broadcasts.
    """
    d = np.abs(np.asarray(distance, dtype=float))
    v = np.asarray(v_max, dtype=float)
    a = np.asarray(a_max, dtype=float)
    cruise = d >= v * v / a
    return np.asarray(np.where(cruise, d / v + v / a, 2.0 * np.sqrt(d / a)))


def ptp_time(nodes: ArrayLike, v_max: ArrayLike, a_max: ArrayLike) -> FloatArray:
    """Time [s] of a point-to-point motion through ``nodes``.

    Args:
        nodes: ``(..., P, nq)`` joint vectors visited in order, at rest at each.
        v_max: ``(nq,)`` velocity limits.
        a_max: ``(nq,)`` acceleration limits.

    Returns:
        ``(...)``: sum over segments of the slowest joint's trapezoid time (the others are
        synchronised to it).
    """
    steps = np.diff(np.asarray(nodes, dtype=float), axis=-2)
    return np.asarray(trapezoid_time(steps, v_max, a_max).max(axis=-1).sum(axis=-1))
