"""A geometric path in its arc length: the parameter the phase-plane timing works in.

:mod:`planning.curves.path_timing` times a path by its speed along the arc length ``s``,
each joint measured in seconds at its velocity limit, so that the velocity limits become
one bound on ``s'``. :func:`arc_length_path` gives the path's first and second derivatives
in ``s`` on a grid and a table to interpolate positions at any arc length.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from planning.curves.torque_limits import TorqueRows
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]

GRID = 512
"""Grid points of the phase-plane profile along the path (uniform in its parameter)."""
FINE = 2049
"""Samples of the path's parameter: its arc length is integrated on them, and positions
along the path are interpolated between them (chords of 1/2048 of the path)."""
STILL_S = 1e-9
"""Arc length below which a path does not move [s at the velocity limits]: the rounding of a
spline through equal nodes leaves about 1e-13."""


class ArcLengthPath(NamedTuple):
    """A path in arc length (:func:`arc_length_path`)."""

    dq: FloatArray
    """``dq/ds`` at the grid points ``(G, nj)``."""
    ddq: FloatArray
    """``d2q/ds2`` at the grid points ``(G, nj)``."""
    ds: FloatArray
    """Steps between the grid points ``(G - 1,)``."""
    length: FloatArray
    """Arc length at the fine samples ``(FINE,)``."""
    table: FloatArray
    """Positions at the fine samples ``(FINE, nj)``."""
    u: FloatArray
    """The path's own parameter at the grid points ``(G,)`` (``path(u)``: their positions)."""
    torque: TorqueRows | None = None
    """Torque constraints at the grid points, if the timing keeps any
    (:func:`planning.curves.torque_limits.torque_rows`)."""


def arc_length_path(path: Trajectory, velocity: FloatArray) -> ArcLengthPath:
    """``path`` in its arc length ``s``, on a grid uniform in its own parameter ``u``.

    ``s`` measures each joint in seconds at its velocity limit ``velocity`` ``(nj,)``
    [rad/s, m/s]. A grid uniform in ``u`` is dense in ``s`` where the path is slow in ``u``:
    at its ends and where it turns sharply, which is where the phase plane needs resolution.
    The derivatives follow from the chain rule exactly (``q' / s'`` and
    ``(q'' - dq/ds s'') / s'^2``); where ``q'`` vanishes they take their neighbours' values.

    Raises:
        PlanningError: the path does not move (its arc length is at most :data:`STILL_S`).
    """
    fine = np.linspace(path.knots[0], path.knots[-1], FINE)
    rate = np.linalg.norm(path(fine, 1) / velocity, axis=1)
    length = np.concatenate([[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(fine))])
    if not length[-1] > STILL_S:
        raise PlanningError(
            f"the path does not move ({length[-1]:.3g} s at the velocity limits, at most {STILL_S:g} s): "
            "there is nothing to time"
        )
    pick = np.linspace(0, FINE - 1, GRID).round().astype(int)
    u, s = fine[pick], length[pick]
    d1, d2 = path(u, 1), path(u, 2)
    speed = rate[pick]
    moving = speed > 1e-9 * speed.max()
    dq = np.zeros_like(d1)
    ddq = np.zeros_like(d2)
    dq[moving] = d1[moving] / speed[moving, None]
    bend = np.sum(d1[moving] * d2[moving] / velocity**2, axis=1) / speed[moving]  # s''(u)
    ddq[moving] = (d2[moving] - dq[moving] * bend[:, None]) / speed[moving, None] ** 2
    for index in np.flatnonzero(~moving):  # take the nearest moving neighbour's values
        nearest = np.flatnonzero(moving)[np.argmin(np.abs(np.flatnonzero(moving) - index))]
        dq[index], ddq[index] = dq[nearest], ddq[nearest]
    steps = np.diff(s)
    keep = np.concatenate([[True], steps > 0])  # drop repeated points (the path standing still)
    return ArcLengthPath(dq[keep], ddq[keep], np.diff(s[keep]), length, path(fine), u[keep])
