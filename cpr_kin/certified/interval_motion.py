"""How far a robot point may move between two samples of a curve: the certified checks' slack.

:func:`cpr_kin.check_curve` and :func:`cpr_kin.certified.self_curve.check_self_curve` bound the
clearance between neighbouring samples by their values minus the robot's motion in between.
One speed bound for the whole curve is its peak, reached mid-motion; near the ends, where a
trajectory starts and stops at rest and often passes closest to an obstacle (a grasp, a
placement), the robot moves far slower, and an interval's own speed bound
(:data:`IntervalSpeed`) certifies what the peak cannot.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

FloatArray = NDArray[np.float64]

IntervalSpeed = Callable[[FloatArray], FloatArray]
"""Sample times ``(K,)`` [s] -> ``(K - 1,)`` bounds on the robot's point speed over each
interval between them [m/s] (e.g. ``motion_radii @`` a trajectory's
:meth:`~planning.curves.trajectory.Trajectory.speed_bounds`)."""


def interval_motion(
    times: FloatArray, point_speed: float, interval_speed: IntervalSpeed | None
) -> FloatArray:
    """``(K - 1,)`` how far any robot point may move between neighbouring ``times`` [m].

    ``point_speed`` bounds the speed on the whole curve [m/s]; ``interval_speed``, when
    given, per interval; the lower of the two counts.
    """
    speed = np.full(len(times) - 1, float(point_speed))
    if interval_speed is not None and len(times) > 1:
        speed = np.minimum(speed, interval_speed(times))
    return np.asarray(speed * np.diff(times))
