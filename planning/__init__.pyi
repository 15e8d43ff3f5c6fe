"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .curves.ptp import ptp_time, trapezoid_time
from .curves.spline import SepticSplineSolver, SplineFit, fit_septic_spline, uniform_knots
from .curves.spline_settings import SplineSettings
from .curves.trajectory import Extrema, Trajectory
from .errors import (
    CprPlanError,
    NoSolutionError,
    NoTrajectoryFoundError,
    PayloadTooHeavyError,
    PlanningError,
    SceneError,
    SplineError,
    TargetOutOfReachError,
)
from .io.bundled import paper_scene
from .io.scene_file import dump_scene, load_scene, load_scene_file
from .io.trajectory_io import write_samples, write_trajectory
from .io.trajectory_reader import TrajectoryFileError, read_trajectory
from .pipeline.metrics import Metrics
from .pipeline.objective import Breakdown, WaypointObjective
from .pipeline.planner import plan, solve
from .pipeline.problem import Problem, build_problem, with_planner
from .pipeline.result import PlanResult
from .pipeline.scene import DEFAULT_SAFETY_MARGIN_M, DEFAULT_SPLINE, Scene
from .pipeline.seeding import Seeds, seed_search
from .pipeline.settings import DEFAULT_FIREFLY, PAPER_SEARCH, PlannerSettings
from .pipeline.target import Target
from .pipeline.torques import TorqueProfile, torque_profile
from .pipeline.tuning import SearchTuning, SeedingTuning
from .pipeline.verification import Requirements, Verification, verify_trajectory
from .search.firefly import FireflyProgress, firefly_minimize
from .search.firefly_settings import FireflySettings
from .search.optimizer import Optimizer, SearchResult
from .search.refined_firefly import RefinedFirefly
from .search.refinement_settings import RefinementSettings
from .warming import warm_up

__all__ = [
    "DEFAULT_FIREFLY",
    "DEFAULT_SAFETY_MARGIN_M",
    "DEFAULT_SPLINE",
    "PAPER_SEARCH",
    "Breakdown",
    "CprPlanError",
    "Extrema",
    "FireflyProgress",
    "FireflySettings",
    "Metrics",
    "NoSolutionError",
    "NoTrajectoryFoundError",
    "Optimizer",
    "PayloadTooHeavyError",
    "PlanResult",
    "PlannerSettings",
    "PlanningError",
    "Problem",
    "RefinedFirefly",
    "RefinementSettings",
    "Requirements",
    "Scene",
    "SceneError",
    "SearchResult",
    "SearchTuning",
    "SeedingTuning",
    "Seeds",
    "SepticSplineSolver",
    "SplineError",
    "SplineFit",
    "SplineSettings",
    "Target",
    "TargetOutOfReachError",
    "TorqueProfile",
    "Trajectory",
    "TrajectoryFileError",
    "Verification",
    "WaypointObjective",
    "build_problem",
    "dump_scene",
    "firefly_minimize",
    "fit_septic_spline",
    "load_scene",
    "load_scene_file",
    "paper_scene",
    "plan",
    "ptp_time",
    "read_trajectory",
    "seed_search",
    "solve",
    "torque_profile",
    "trapezoid_time",
    "uniform_knots",
    "verify_trajectory",
    "warm_up",
    "with_planner",
    "write_samples",
    "write_trajectory",
]
