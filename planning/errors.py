"""Exceptions of :mod:`planning`.

Every error caused by user input (settings, waypoints, knots, scenes) is a
:class:`PlanningError`, whose message names the offending value and what is allowed.
"""

from __future__ import annotations


class PlanningError(ValueError):
    """Base class of every error raised by :mod:`planning` on bad input."""


class SplineError(PlanningError):
    """Invalid spline settings, knots or node values."""
