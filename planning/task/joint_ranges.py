"""The joint ranges a tool line's walk keeps: brought in from the limits, pulled from them when redundant.

A walk clips each sample to the joint ranges; a spline through samples that sit at a limit
can pass it by a little, so the walk is redone within ranges brought in by twice that
overshoot (:func:`beyond_range`, :data:`RANGE_INSETS`). On an arm with more joints than the
tool's six directions, the Jacobian's null space pulls joints in the outer :data:`LIMIT_ZONE`
of their range back toward the middle, by :data:`LIMIT_GAIN` of their distance from it, more
the closer they are to the limit (the walk's pull, :mod:`planning.task.line_walk`).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.trajectory import Trajectory

FloatArray = NDArray[np.float64]

LIMIT_ZONE = 0.2
"""The outer share of a joint's range where a redundant arm's null space pulls it back."""
LIMIT_GAIN = 0.01
"""Share of a joint's distance from the middle of its range that one step pulls back, at the limit
(docs/tuning.md, "Tool lines")."""
RANGE_INSETS = 3
"""Most times the walk is redone within ranges brought in by twice its spline's overshoot, where
samples at a joint's limit let the spline pass it."""


def joint_range(robot: ck.Robot, inset: FloatArray | float = 0.0) -> tuple[FloatArray, FloatArray]:
    """The joint ranges, ``inset`` [rad or m] in from each end (at most to the middle)."""
    lower, upper = robot.limits.lower, robot.limits.upper
    inset = np.minimum(inset, 0.5 * (upper - lower))
    return lower + inset, upper - inset


def beyond_range(robot: ck.Robot, path: Trajectory) -> FloatArray:
    """``(nq,)`` how far the path passes each joint's range [rad or m] (0 within it)."""
    lower, upper = joint_range(robot)
    return np.maximum(np.maximum(lower - path.extrema(0).minimum, path.extrema(0).maximum - upper), 0.0)
