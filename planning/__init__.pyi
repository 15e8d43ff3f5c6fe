"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .curves.ptp import ptp_time, trapezoid_time
from .curves.spline import SepticSplineSolver, SplineFit, SplineSettings, fit_septic_spline, uniform_knots
from .curves.trajectory import Extrema, Trajectory
from .errors import PlanningError, SplineError
from .io.trajectory_io import read_trajectory, write_samples, write_trajectory
from .objective import Breakdown, WaypointObjective
from .planner import Metrics, NoTrajectoryFoundError, PlanResult, plan, warm_up
from .scene import PlannerSettings, Scene, Target, paper_scene
from .search.firefly import FireflyProgress, FireflyResult, FireflySettings, firefly_minimize
from .verification import Verification, verify_trajectory

__all__ = [
    "Breakdown",
    "Extrema",
    "FireflyProgress",
    "FireflyResult",
    "FireflySettings",
    "Metrics",
    "NoTrajectoryFoundError",
    "PlanResult",
    "PlannerSettings",
    "PlanningError",
    "Scene",
    "SepticSplineSolver",
    "SplineError",
    "SplineFit",
    "SplineSettings",
    "Target",
    "Trajectory",
    "Verification",
    "WaypointObjective",
    "firefly_minimize",
    "fit_septic_spline",
    "paper_scene",
    "plan",
    "ptp_time",
    "read_trajectory",
    "trapezoid_time",
    "uniform_knots",
    "verify_trajectory",
    "warm_up",
    "write_samples",
    "write_trajectory",
]
