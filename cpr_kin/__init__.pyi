"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .bounds.batch_kinematics import sampled_configurations
from .bounds.close_pairs import ClosePair
from .certified.coarse_first import IntervalSpeed
from .certified.motion import CurveCheck, check_curve, check_segment, motion_radii, path_weights
from .collision.clearance import BatchClearance, Clearance, PairDistance
from .collision.world import CollisionWorld
from .common.errors import (
    CheckStoppedError,
    CprKinError,
    IkMissError,
    JointLimitError,
    ObstacleError,
    UnreachableError,
    UrdfError,
)
from .description.loading import RobotSpec, load_robot
from .description.shared_robots import forget_shared_robots, shared_robot
from .kinematics.carried import carrying, holding_links, left_at, taken_from
from .kinematics.dynamics import Dynamics, Payload, robot_dynamics
from .kinematics.forward import frame_poses, frame_positions
from .kinematics.ik_target import IkTarget
from .kinematics.numerical_ik import IkSettings, solve_ik
from .model.limits import JointLimits
from .model.robot import GROUPS, PositionIk, Robot, RobotGeometry
from .presets import (
    CPR_JOINTS,
    TCP_FRAME,
    cpr_limits_path,
    cpr_spec,
    cpr_urdf_path,
    load_cpr,
    robot_spec,
    tcp_ik,
)
from .shapes.obstacles import SHAPES, Obstacle

__all__ = [
    "CPR_JOINTS",
    "GROUPS",
    "SHAPES",
    "TCP_FRAME",
    "BatchClearance",
    "CheckStoppedError",
    "Clearance",
    "ClosePair",
    "CollisionWorld",
    "CprKinError",
    "CurveCheck",
    "Dynamics",
    "IkMissError",
    "IkSettings",
    "IkTarget",
    "IntervalSpeed",
    "JointLimitError",
    "JointLimits",
    "Obstacle",
    "ObstacleError",
    "PairDistance",
    "Payload",
    "PositionIk",
    "Robot",
    "RobotGeometry",
    "RobotSpec",
    "UnreachableError",
    "UrdfError",
    "carrying",
    "check_curve",
    "check_segment",
    "cpr_limits_path",
    "cpr_spec",
    "cpr_urdf_path",
    "forget_shared_robots",
    "frame_poses",
    "frame_positions",
    "holding_links",
    "left_at",
    "load_cpr",
    "load_robot",
    "motion_radii",
    "path_weights",
    "robot_dynamics",
    "robot_spec",
    "sampled_configurations",
    "shared_robot",
    "solve_ik",
    "taken_from",
    "tcp_ik",
]
