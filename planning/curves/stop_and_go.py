"""A motion that follows a polyline exactly: straight joint-space segments, at rest at every vertex.

Each segment is timed on its own (:func:`~planning.curves.path_timing.time_path`: the fastest
jerk-limited, C3 rest-to-rest motion along it); the segments are joined at their vertices,
where the robot stands still with zero velocity, acceleration and jerk, so the whole is C3.
A timed straight segment never leaves it: the timing's moving average and its septic
segments combine collinear positions with weights that sum to one, so every configuration
of the motion lies on the line between the segment's vertices (up to rounding). Whatever
was checked clear along the polyline is what the robot sweeps.
"""

from __future__ import annotations

import itertools

import numpy as np
from numpy.typing import NDArray

from planning.curves.path_timing import time_path
from planning.curves.torque_limits import TorqueModel
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]


def stop_and_go(
    vertices: FloatArray,
    velocity: FloatArray,
    acceleration: FloatArray,
    jerk: FloatArray,
    torque: TorqueModel | None = None,
) -> Trajectory:
    """The C3 trajectory through ``vertices`` ``(k, nj)`` along straight lines, at rest at each.

    Args:
        vertices: the polyline's vertices [rad, m], first the start, last the goal; repeated
            vertices are passed once.
        velocity: ``(nj,)`` limits [rad/s, m/s].
        acceleration: ``(nj,)`` limits [rad/s^2, m/s^2].
        jerk: ``(nj,)`` limits [rad/s^3, m/s^3].
        torque: the robot's torques and effort limits; ``None``: kinematic limits only.

    Raises:
        PlanningError: fewer than two distinct vertices, or a limit not finite and positive.
    """
    points = np.asarray(vertices, dtype=float)
    if points.ndim != 2 or len(points) < 2:
        raise PlanningError(f"vertices of shape {points.shape}; expected (k >= 2, joints)")
    moves = np.concatenate([[True], np.any(np.diff(points, axis=0) != 0.0, axis=1)])
    points = points[moves]
    if len(points) < 2:
        raise PlanningError("the polyline does not move: every vertex is the start")
    segments = [
        time_path(_line(a, b), velocity, acceleration, jerk, torque=torque, still_jerk=True)
        for a, b in itertools.pairwise(points)
    ]
    return joined(segments)


def joined(trajectories: list[Trajectory]) -> Trajectory:
    """``trajectories`` one after the other, each starting where and when the one before ends."""
    knots, coefficients, start = [np.zeros(1)], [], 0.0
    for trajectory in trajectories:
        local = trajectory.knots - trajectory.knots[0]
        knots.append(start + local[1:])
        coefficients.append(trajectory.coefficients)
        start += float(local[-1])
    return Trajectory(np.concatenate(knots), np.concatenate(coefficients))


def _line(a: FloatArray, b: FloatArray) -> Trajectory:
    """The straight path from ``a`` to ``b`` over one unit of its parameter, as a septic polynomial."""
    coefficients = np.zeros((1, len(a), 8))
    coefficients[0, :, 0], coefficients[0, :, 1] = a, b - a
    return Trajectory(np.array([0.0, 1.0]), coefficients)
