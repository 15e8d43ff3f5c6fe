"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from . import baselines
from .firefly import FireflyProgress, firefly_minimize
from .firefly_settings import FireflySettings
from .optimizer import BatchObjective, Optimizer, SearchResult
from .refinement import cma_refine, refine_search
from .rrt_connect import Relaxation, RrtPath
from .rrt_settings import RrtSettings
from .waypoints import waypoints_along

__all__ = [
    "BatchObjective",
    "FireflyProgress",
    "FireflySettings",
    "Optimizer",
    "Relaxation",
    "RrtPath",
    "RrtSettings",
    "SearchResult",
    "baselines",
    "cma_refine",
    "firefly_minimize",
    "refine_search",
    "waypoints_along",
]
