"""A spline through samples of a path, as a :class:`~planning.curves.trajectory.Trajectory`.

The interpolating B-spline of odd degree with de Boor's not-a-knot knots, the one
:func:`scipy.interpolate.make_interp_spline` builds (compiled here:
:mod:`planning.curves.bspline_kernels`), in the piecewise-power layout every trajectory here
uses: each piece's coefficients are its Taylor series about its left end.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planning.curves.bspline_kernels import interpolating_coefficients, power_pieces
from planning.curves.trajectory import Trajectory
from planning.errors import SplineError

FloatArray = NDArray[np.float64]

ORDER = 8
"""Coefficients per piece of the trajectory layout (septic)."""
DEGREES = (1, 3, 5, 7)
"""The degrees a spline through samples may have: odd (the not-a-knot knots), at most the layout's."""


def spline_through(parameter: FloatArray, samples: FloatArray, degree: int = 5) -> Trajectory:
    """The interpolating spline of ``degree`` through ``samples`` ``(n, nq)`` at ``parameter`` ``(n,)``.

    A quintic (the default) is C4: a motion timed along it has a continuous jerk.

    Raises:
        SplineError: ``degree`` not one of :data:`DEGREES`, ``parameter`` not strictly
            increasing, or no more samples than ``degree``.
    """
    sites = np.ascontiguousarray(parameter, dtype=float)
    values = np.ascontiguousarray(samples, dtype=float)
    if degree not in DEGREES:
        raise SplineError(f"spline degree = {degree}; give one of {list(DEGREES)}")
    if values.ndim != 2 or sites.shape != values.shape[:1] or len(sites) <= degree:
        raise SplineError(
            f"a spline of degree {degree} needs more than {degree} samples (n, nq) at n parameters; "
            f"got samples {values.shape} at parameters {sites.shape}"
        )
    steps = np.diff(sites)
    if not np.all(steps > 0.0):
        at = int(np.argmin(steps))
        raise SplineError(
            f"spline parameters must increase strictly; parameter[{at + 1}] = {float(sites[at + 1])!r} "
            f"follows {float(sites[at])!r}"
        )
    knots = not_a_knot(sites, degree)
    coefficients = interpolating_coefficients(knots, degree, sites, values)
    breaks = knots[degree : len(sites) + 1]  # the distinct knots: the pieces' ends
    return Trajectory(breaks, power_pieces(knots, degree, coefficients, ORDER))


def not_a_knot(sites: FloatArray, degree: int) -> FloatArray:
    """``(n + degree + 1,)`` de Boor's not-a-knot knots of ``n`` sites, for an odd ``degree``.

    ``degree + 1`` knots at each end; between them the sites, but the ``(degree - 1) / 2`` next
    to each end.
    """
    skip = (degree - 1) // 2
    inner = sites[skip + 1 : len(sites) - skip - 1]
    return np.concatenate([np.full(degree + 1, sites[0]), inner, np.full(degree + 1, sites[-1])])


def chord_lengths(samples: FloatArray) -> FloatArray:
    """``(n,)`` the length of the polyline through ``samples`` ``(n, nq)`` up to each, from 0."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(samples, axis=0), axis=1))])


def chord_parameter(samples: FloatArray) -> FloatArray:
    """``(n,)`` the samples' normalised chord lengths, 0 to 1 (evenly spaced if they do not move)."""
    lengths = chord_lengths(samples)
    return lengths / lengths[-1] if lengths[-1] > 0 else np.linspace(0.0, 1.0, len(samples))
