"""Point-to-point timing: synchronised rest-to-rest trapezoidal moves (paper's t_sol)."""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from cpr_kin.common.rest_to_rest import trapezoid_time

__all__ = ["ptp_time", "trapezoid_time"]  # trapezoid_time: planning's API since the paper case

FloatArray = NDArray[np.float64]


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
