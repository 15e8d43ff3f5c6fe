"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from . import baselines
from .firefly import FireflyProgress, firefly_minimize
from .firefly_settings import FireflySettings
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
