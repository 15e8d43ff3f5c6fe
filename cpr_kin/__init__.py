"""cpr_kin: the CPR cylindrical manipulator (R-P-P:R-R) as a Pinocchio/coal model.

Kinematics, analytic inverse kinematics of the tool-centre point, and signed clearance of
the robot's collision groups to static obstacles, for single configurations, batches and
whole joint-space curves. Nothing here draws or plans.
"""

from cpr_kin.collision import BatchClearance, Clearance, CollisionWorld, PairDistance
from cpr_kin.errors import CprKinError, JointLimitError, ObstacleError, UnreachableError, UrdfError
from cpr_kin.ik import tcp_ik
from cpr_kin.kinematics import frame_poses, frame_positions
from cpr_kin.limits import JointLimits
from cpr_kin.motion import CurveCheck, check_curve, check_segment, motion_radii
from cpr_kin.obstacles import SHAPES, Obstacle
from cpr_kin.resources import cpr_limits_path, cpr_urdf_path
from cpr_kin.robot import CPR_JOINTS, GROUPS, TCP_FRAME, Robot, RobotGeometry, load_cpr

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
    "UnreachableError",
    "UrdfError",
    "check_curve",
    "check_segment",
    "cpr_limits_path",
    "cpr_urdf_path",
    "frame_poses",
    "frame_positions",
    "load_cpr",
    "motion_radii",
    "tcp_ik",
]
