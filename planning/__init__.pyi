"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .errors import PlanningError, SplineError
from .firefly import FireflyProgress, FireflyResult, FireflySettings, firefly_minimize
from .objective import Breakdown, WaypointObjective
from .planner import Metrics, NoTrajectoryFoundError, PlanResult, plan, warm_up
from .ptp import ptp_time, trapezoid_time
from .scene import PlannerSettings, Scene, Target, paper_scene
from .spline import SepticSplineSolver, SplineFit, SplineSettings, fit_septic_spline, uniform_knots
from .trajectory import Extrema, Trajectory
from .trajectory_io import read_trajectory, write_samples, write_trajectory
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
