"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .ompl_rrt import import_peer, plan_rrt_connect
from .pyroboplan_rrt import plan_pyroboplan_rrt_connect, shortcut_path
from .roboplan_rrt import PeerResult, RoboplanPeer
from .ruckig_bound import free_space_bound, ruckig_duration
from .toppra_timing import SamplingResult, import_toppra, planning_clearance_m, time_and_verify

__all__ = [
    "PeerResult",
    "RoboplanPeer",
    "SamplingResult",
    "free_space_bound",
    "import_peer",
    "import_toppra",
    "plan_pyroboplan_rrt_connect",
    "plan_rrt_connect",
    "planning_clearance_m",
    "ruckig_duration",
    "shortcut_path",
    "time_and_verify",
]
