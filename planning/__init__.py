"""planning: firefly waypoint search, septic smoothing spline and the planner pipeline.

Build a :class:`Scene` (or take :func:`paper_scene`), call :func:`plan`, and inspect the
immutable :class:`PlanResult`: the verified trajectory, its waypoints, metrics, the
optimiser's history and the verification. Write it with :func:`write_trajectory`.
"""

from planning.errors import PlanningError, SplineError
from planning.firefly import FireflyProgress, FireflyResult, FireflySettings, firefly_minimize
from planning.objective import Breakdown, WaypointObjective
from planning.planner import Metrics, NoTrajectoryFoundError, PlanResult, plan, warm_up
from planning.ptp import ptp_time, trapezoid_time
from planning.scene import PlannerSettings, Scene, Target, paper_scene
from planning.spline import SepticSplineSolver, SplineFit, SplineSettings, fit_septic_spline, uniform_knots
from planning.trajectory import Extrema, Trajectory
from planning.trajectory_io import read_trajectory, write_samples, write_trajectory
from planning.verification import Verification, verify_trajectory

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
