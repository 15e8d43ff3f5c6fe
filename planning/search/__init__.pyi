"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from . import baselines
from .firefly import FireflyProgress, FireflySettings, firefly_minimize
from .optimizer import BatchObjective, Optimizer, SearchResult

__all__ = [
    "BatchObjective",
    "FireflyProgress",
    "FireflySettings",
    "Optimizer",
    "SearchResult",
    "baselines",
    "firefly_minimize",
]
