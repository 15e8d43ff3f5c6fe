"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .carried import carrying
from .clearance import BatchClearance, Clearance, PairDistance
from .close_pairs import ClosePair
from .collision import CollisionWorld
from .dynamics import Dynamics, Payload, robot_dynamics
from .errors import CprKinError, IkMissError, JointLimitError, ObstacleError, UnreachableError, UrdfError
from .interval_motion import IntervalSpeed
from .kinematics import frame_poses, frame_positions
from .limits import JointLimits, sampled_configurations
from .loading import RobotSpec, load_robot
from .motion import CurveCheck, check_curve, check_segment, motion_radii, path_weights
from .numerical_ik import IkSettings, IkTarget, solve_ik
from .obstacles import SHAPES, Obstacle
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
from .robot import GROUPS, PositionIk, Robot, RobotGeometry

__all__ = [
    "CPR_JOINTS",
    "GROUPS",
    "SHAPES",
    "TCP_FRAME",
    "BatchClearance",
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
    "frame_poses",
    "frame_positions",
    "load_cpr",
    "load_robot",
    "motion_radii",
    "path_weights",
    "robot_dynamics",
    "robot_spec",
    "sampled_configurations",
    "solve_ik",
    "tcp_ik",
]
