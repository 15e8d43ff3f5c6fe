"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from . import baselines
from .baselines import Optimizer
from .firefly import BatchObjective, FireflyProgress, FireflyResult, FireflySettings, firefly_minimize

__all__ = [
    "BatchObjective",
    "FireflyProgress",
    "FireflyResult",
    "FireflySettings",
    "Optimizer",
    "baselines",
    "firefly_minimize",
]
