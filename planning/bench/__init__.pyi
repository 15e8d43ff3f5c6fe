"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .arm_scenes import blocked_scene
from .narrow_passages import narrow_scene
from .ompl_rrt import import_peer, plan_rrt_connect
from .pyroboplan_rrt import plan_pyroboplan_rrt_connect, shortcut_path
from .roboplan_rrt import PeerResult, RoboplanPeer
from .ruckig_bound import free_space_bound, ruckig_duration
from .scene_generator import generate_scenes, random_scene
from .toppra_timing import SamplingResult, import_toppra, planning_clearance_m, time_and_verify

__all__ = [
    "PeerResult",
    "RoboplanPeer",
    "SamplingResult",
    "blocked_scene",
    "free_space_bound",
    "generate_scenes",
    "import_peer",
    "import_toppra",
    "narrow_scene",
    "plan_pyroboplan_rrt_connect",
    "plan_rrt_connect",
    "planning_clearance_m",
    "random_scene",
    "ruckig_duration",
    "shortcut_path",
    "time_and_verify",
]
