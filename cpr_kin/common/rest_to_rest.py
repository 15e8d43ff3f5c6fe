"""The shortest rest-to-rest move of one joint under its speed and acceleration limits.

Shared by the robot package (how soon a joint configuration is reached:
:meth:`~cpr_kin.model.limits.JointLimits.move_time_s`) and the planner (the paper's point-to-point
time ``t_sol``, :mod:`planning.curves.ptp`).
"""

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
