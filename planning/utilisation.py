"""How much of each limit a trajectory uses, over time: kinematic, and the joint torques.

A trajectory that touches a limit once and runs far below it elsewhere leaves time on the
table; one that runs along its limits is near time-optimal. :func:`limit_usage` samples the
largest ``|q_j^(r)| / limit_j^(r)`` over the joints, for velocity, acceleration and jerk
(``r = 1, 2, 3``), and which joint it is; :class:`LimitUsage` summarises it (time-averaged
usage, share of the time near a limit, the usage phase by phase). Given the robot's dynamics,
``|torque_j| / effort_j`` is a fourth order (``"torque"``). The report, ``samples.csv``
and ``utilisation.png`` show it.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from planning.curves.trajectory import Trajectory

if TYPE_CHECKING:  # types only: limits are read as arrays, the robot model is not loaded
    import cpr_kin as ck

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

ORDERS = ("velocity", "acceleration", "jerk")
"""The limited derivatives, in order ``r = 1, 2, 3``."""
TORQUE = "torque"
"""The order after them when the usage includes the joint torques."""
NEAR_LIMIT = 0.95
"""Usage from which a sample counts as running at its limit."""
SUMMARY_SAMPLES = 1001
"""Samples over the duration from which the summary figures are taken."""


@dataclass(frozen=True)
class LimitUsage:
    """Limit usage of a trajectory at sample times.

    Attributes:
        times: ``(T,)`` sample times [s], increasing, from the start to the end.
        usage: ``(T, K)`` largest ``|derivative| / limit`` over the joints, per order
            (:attr:`orders`).
        binding: ``(T, K)`` the joint (index) that has it.
        orders: the orders: :data:`ORDERS`, then :data:`TORQUE` if the torques are included.
    """

    times: FloatArray
    usage: FloatArray
    binding: IntArray
    orders: tuple[str, ...] = ORDERS

    def mean(self) -> FloatArray:
        """``(K,)`` time-averaged usage per order (trapezoidal rule)."""
        if self.times[-1] <= self.times[0]:
            return np.asarray(self.usage.mean(axis=0))
        return np.asarray(np.trapezoid(self.usage, self.times, axis=0) / (self.times[-1] - self.times[0]))

    def share_near_limit(self, threshold: float = NEAR_LIMIT) -> FloatArray:
        """``(K + 1,)`` share of the samples at which each order, then any, is used ``>= threshold``."""
        near = self.usage >= threshold
        return np.append(near.mean(axis=0), near.any(axis=1).mean())

    def phases(self, count: int = 10) -> list[tuple[float, float, FloatArray, int, int]]:
        """The usage in ``count`` equal spans of time: ``(t0, t1, peak usage (K,), order, joint)``.

        ``order`` and ``joint`` name the limit closest to binding in the span.
        """
        edges = np.linspace(self.times[0], self.times[-1], count + 1)
        rows = []
        for t0, t1 in pairwise(edges):
            inside = (self.times >= t0) & (self.times <= t1)
            if not inside.any():  # a span between two samples: the nearer sample
                inside = np.abs(self.times - 0.5 * (t0 + t1)) == np.min(np.abs(self.times - 0.5 * (t0 + t1)))
            peak = self.usage[inside].max(axis=0)
            order = int(np.argmax(peak))
            sample = np.flatnonzero(inside)[int(np.argmax(self.usage[inside, order]))]
            rows.append((float(t0), float(t1), peak, order, int(self.binding[sample, order])))
        return rows


def limit_usage(
    trajectory: Trajectory,
    limits: ck.JointLimits,
    times: FloatArray | None = None,
    dynamics: ck.Dynamics | None = None,
) -> LimitUsage:
    """The usage of ``limits`` by ``trajectory`` at ``times`` [s].

    By default :data:`SUMMARY_SAMPLES` times evenly spaced over its duration. With
    ``dynamics`` whose efforts are known, the torques' usage too (:data:`TORQUE`).
    """
    if times is None:
        times = np.linspace(trajectory.knots[0], trajectory.knots[-1], SUMMARY_SAMPLES)
    times = np.asarray(times, dtype=float)
    bounds = (limits.velocity, limits.acceleration, limits.jerk)
    ratios = [np.abs(trajectory(times, r)) / bounds[r - 1] for r in (1, 2, 3)]
    orders: tuple[str, ...] = ORDERS
    if dynamics is not None and dynamics.limited:
        torques = dynamics.torques(trajectory(times), trajectory(times, 1), trajectory(times, 2))
        ratios.append(dynamics.utilisation(torques))
        orders = (*ORDERS, TORQUE)
    stacked = np.stack(ratios, axis=1)  # (T, K, nj)
    return LimitUsage(times=times, usage=stacked.max(axis=2), binding=stacked.argmax(axis=2), orders=orders)
