"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .choose import Choice, Refusal
from .metrics import Elapsed, Metrics
from .motion import Motion
from .objective import Breakdown, WaypointObjective
from .offered import Offered, Timing
from .planner import plan, solve
from .problem import Problem, build_problem, with_planner
from .result import PlanResult
from .scene import DEFAULT_SAFETY_MARGIN_M, DEFAULT_SPLINE, Scene
from .search import planner_search
from .seeding import Attempt, Seeds, seed_search
from .settings import DEFAULT_FIREFLY, PAPER_SEARCH, PlannerSettings
from .target import Target
from .timing import FixedDuration, FreeDuration
from .tuning import SearchTuning, SeedingTuning
from .verification import Verification, verify_trajectory

__all__ = [
    "DEFAULT_FIREFLY",
    "DEFAULT_SAFETY_MARGIN_M",
    "DEFAULT_SPLINE",
    "PAPER_SEARCH",
    "Attempt",
    "Breakdown",
    "Choice",
    "Elapsed",
    "FixedDuration",
    "FreeDuration",
    "Metrics",
    "Motion",
    "Offered",
    "PlanResult",
    "PlannerSettings",
    "Problem",
    "Refusal",
    "Scene",
    "SearchTuning",
    "SeedingTuning",
    "Seeds",
    "Target",
    "Timing",
    "Verification",
    "WaypointObjective",
    "build_problem",
    "plan",
    "planner_search",
    "seed_search",
    "solve",
    "verify_trajectory",
    "with_planner",
]
