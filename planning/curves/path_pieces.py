"""Paths made of other paths: piecewise polynomials cut, reparameterised, bridged and joined.

All exact: a cut inside a segment re-expands its polynomial about the cut (a Taylor shift), a
reparameterisation scales the r-th coefficient by the r-th power of the ratio, and a bridge is
the septic Hermite polynomial with given position and first three derivatives at both ends
(:data:`~planning.curves.hermite.HERMITE_INV`), so that what it joins stays C3.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from math import comb

import numpy as np
from numpy.typing import NDArray

from planning.curves.hermite import HERMITE_INV, ORDER, node_scaling
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError

FloatArray = NDArray[np.float64]

_SHIFT = np.array([[comb(j, k) for j in range(ORDER)] for k in range(ORDER)], dtype=float)
"""``_SHIFT[k, j] = C(j, k)``: the binomials of a Taylor shift."""


def split_at(trajectory: Trajectory, times: Sequence[float]) -> Trajectory:
    """``trajectory`` with knots added at ``times`` (inside its span), the same function exactly.

    Raises:
        PlanningError: a time outside the trajectory's span.
    """
    knots, coefficients = list(trajectory.knots), list(trajectory.coefficients)
    for t in sorted(float(t) for t in times):
        if not knots[0] <= t <= knots[-1]:
            raise PlanningError(f"t = {t:g} s is outside the trajectory's [{knots[0]:g}, {knots[-1]:g}] s")
        i = int(np.searchsorted(knots, t, side="right")) - 1
        if i >= len(coefficients) or abs(knots[i] - t) <= 1e-12 or abs(knots[i + 1] - t) <= 1e-12:
            continue  # a knot already
        h = t - knots[i]
        powers = h ** np.maximum(np.arange(ORDER)[None, :] - np.arange(ORDER)[:, None], 0)
        shift = np.triu(_SHIFT * powers)  # c'_k = sum_j C(j, k) h^(j-k) c_j
        right = coefficients[i] @ shift.T
        knots.insert(i + 1, t)
        coefficients.insert(i + 1, right)
    return Trajectory(np.array(knots), np.array(coefficients))


def piece(trajectory: Trajectory, start: float, end: float) -> Trajectory:
    """The part of ``trajectory`` over ``[start, end]``, cut exactly (its own knots kept)."""
    cut = split_at(trajectory, [start, end])
    first, last = (int(np.argmin(np.abs(cut.knots - t))) for t in (start, end))
    return Trajectory(cut.knots[first : last + 1], cut.coefficients[first:last])


def rescaled(trajectory: Trajectory, start: float, length: float) -> Trajectory:
    """The same path over ``[start, start + length]`` of a new parameter, linearly mapped."""
    scaled = trajectory.time_scaled(length / trajectory.duration)
    return Trajectory(scaled.knots - scaled.knots[0] + start, scaled.coefficients)


def bridge(start: FloatArray, end: FloatArray, at: float, length: float) -> Trajectory:
    """The septic over ``[at, at + length]`` whose ends take ``start`` and ``end`` ``(4, nj)`` (q to q''')."""
    data = np.concatenate([np.asarray(start), np.asarray(end)]).T  # (nj, 8)
    scaled = data * node_scaling(np.array(length))
    origin = scaled[:, 0].copy()  # solved about its first position, as the timing's segments are
    scaled[:, [0, 4]] -= origin[:, None]
    coefficients = (scaled @ HERMITE_INV.T) * length ** -np.arange(float(ORDER))
    coefficients[:, 0] += origin
    return Trajectory(np.array([at, at + length]), coefficients[None])


def joined_paths(paths: Sequence[Trajectory]) -> Trajectory:
    """``paths`` one after the other, each starting at the parameter where the one before ends."""
    for before, after in itertools.pairwise(paths):
        if abs(before.knots[-1] - after.knots[0]) > 1e-9:
            raise PlanningError("paths to join must meet: each starts where the one before ends")
    knots = np.concatenate([paths[0].knots, *[p.knots[1:] for p in paths[1:]]])
    return Trajectory(knots, np.concatenate([p.coefficients for p in paths]))


def ends(trajectory: Trajectory, at: float) -> FloatArray:
    """``(4, nj)`` the position and first three derivatives at ``at``."""
    return np.stack([trajectory(np.array([at]), r)[0] for r in range(4)])
