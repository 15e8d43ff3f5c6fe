"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .piecewise_sampler import PiecewiseSampler
from .polynomial_bounds import DerivativeBounds, bernstein_matrix
from .ptp import ptp_time, trapezoid_time
from .spline import (
    DENSE_MAP_NODES,
    SepticSplineSolver,
    SplineFit,
    fit_septic_spline,
    uniform_knots,
)
from .spline_settings import SplineSettings
from .trajectory import DERIVATIVE_NAMES, Extrema, Trajectory

__all__ = [
    "DENSE_MAP_NODES",
    "DERIVATIVE_NAMES",
    "DerivativeBounds",
    "Extrema",
    "PiecewiseSampler",
    "SepticSplineSolver",
    "SplineFit",
    "SplineSettings",
    "Trajectory",
    "bernstein_matrix",
    "fit_septic_spline",
    "ptp_time",
    "trapezoid_time",
    "uniform_knots",
]
