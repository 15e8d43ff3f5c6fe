"""planning: firefly waypoint search, septic smoothing spline and the planner pipeline.

Available now: the septic (degree-7) smoothing spline of Simon (2004) as used by the paper,
and the piecewise-polynomial trajectory it produces.
"""

from planning.errors import PlanningError, SplineError
from planning.spline import SepticSplineSolver, SplineFit, SplineSettings, fit_septic_spline, uniform_knots
from planning.trajectory import Extrema, Trajectory

__all__ = [
    "Extrema",
    "PlanningError",
    "SepticSplineSolver",
    "SplineError",
    "SplineFit",
    "SplineSettings",
    "Trajectory",
    "fit_septic_spline",
    "uniform_knots",
]
