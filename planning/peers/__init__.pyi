"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .ompl_rrt import SamplingResult, plan_rrt_connect
from .pyroboplan_rrt import plan_pyroboplan_rrt_connect

__all__ = [
    "SamplingResult",
    "plan_pyroboplan_rrt_connect",
    "plan_rrt_connect",
]
