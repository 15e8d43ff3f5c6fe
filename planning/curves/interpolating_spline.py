"""A spline through samples of a path, as a :class:`~planning.curves.trajectory.Trajectory`.

scipy's interpolating B-spline (:func:`scipy.interpolate.make_interp_spline`) turned into the
piecewise-power layout every trajectory here uses: each piece's coefficients are its Taylor
series about its left end, computed from the spline's derivatives at the piece's middle (inside
the piece, so no knot's side is in doubt).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import BSpline, make_interp_spline

from cpr_kin.common.arrays import distinct_sorted
from planning.curves.trajectory import Trajectory

FloatArray = NDArray[np.float64]

ORDER = 8
"""Coefficients per piece of the trajectory layout (septic)."""


def spline_through(parameter: FloatArray, samples: FloatArray, degree: int = 5) -> Trajectory:
    """The interpolating spline of ``degree`` through ``samples`` ``(n, nq)`` at ``parameter`` ``(n,)``.

    A quintic (the default) is C4: a motion timed along it has a continuous jerk. ``degree``
    is at most 7, the trajectory layout's; ``n`` must exceed it.
    """
    spline = make_interp_spline(parameter, samples, k=degree, axis=0)
    breaks = distinct_sorted(spline.t)
    middles = 0.5 * (breaks[1:] + breaks[:-1])
    coefficients = np.zeros((len(middles), samples.shape[1], ORDER))
    for power in range(degree + 1):
        coefficients[:, :, power] = _taylor(spline, middles, breaks[:-1] - middles, power)
    return Trajectory(breaks, coefficients)


def chord_lengths(samples: FloatArray) -> FloatArray:
    """``(n,)`` the length of the polyline through ``samples`` ``(n, nq)`` up to each, from 0."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(samples, axis=0), axis=1))])


def chord_parameter(samples: FloatArray) -> FloatArray:
    """``(n,)`` the samples' normalised chord lengths, 0 to 1 (evenly spaced if they do not move)."""
    lengths = chord_lengths(samples)
    return lengths / lengths[-1] if lengths[-1] > 0 else np.linspace(0.0, 1.0, len(samples))


def _taylor(spline: BSpline, at: FloatArray, shift: FloatArray, power: int) -> FloatArray:
    """``(n, nq)`` the ``power``-th Taylor coefficient at ``at + shift`` of the pieces around ``at``."""
    degree = int(spline.k)
    total = np.zeros((len(at), spline.c.shape[1]))
    for r in range(power, degree + 1):
        scale = shift[:, None] ** (r - power) / (math.factorial(power) * math.factorial(r - power))
        total += spline(at, nu=r) * scale
    return total
