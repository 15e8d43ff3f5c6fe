"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .clearance import BatchClearance, Clearance, PairDistance
from .collision import CollisionWorld
from .cpr import CPR_JOINTS, TCP_FRAME, cpr_spec, load_cpr
from .errors import CprKinError, JointLimitError, ObstacleError, UnreachableError, UrdfError
from .ik import tcp_ik
from .kinematics import frame_poses, frame_positions
from .limits import JointLimits
from .loading import RobotSpec, load_robot
from .motion import CurveCheck, check_curve, check_segment, motion_radii
from .obstacles import SHAPES, Obstacle
from .resources import cpr_limits_path, cpr_urdf_path
from .robot import GROUPS, Robot, RobotGeometry

__all__ = [
    "CPR_JOINTS",
    "GROUPS",
    "SHAPES",
    "TCP_FRAME",
    "BatchClearance",
    "Clearance",
    "CollisionWorld",
    "CprKinError",
    "CurveCheck",
    "JointLimitError",
    "JointLimits",
    "Obstacle",
    "ObstacleError",
    "PairDistance",
    "Robot",
    "RobotGeometry",
    "RobotSpec",
    "UnreachableError",
    "UrdfError",
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
    "tcp_ik",
]
