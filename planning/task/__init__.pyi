"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .free_motion import FreeMotion, plan_free
from .held_orientation import HeldMotion, hold_orientation
from .line_deviation import LineDeviation, line_deviation
from .line_ik import JointLine, joint_line
from .line_motion import LineMotion, plan_line
from .orientation import OrientationConstraint, OrientationDeviation, orientation_deviation
from .segments import Attach, Detach, Move, Segment, Wait, segment_name
from .task_check import TaskCheck, check_task
from .task_plan import SegmentMotion, TaskMotion, plan_task
from .task_record import record_problems, task_record
from .tool_line import LineGeometry, LineTolerance, ToolLine, ToolPose

__all__ = [
    "Attach",
    "Detach",
    "FreeMotion",
    "HeldMotion",
    "JointLine",
    "LineDeviation",
    "LineGeometry",
    "LineMotion",
    "LineTolerance",
    "Move",
    "OrientationConstraint",
    "OrientationDeviation",
    "Segment",
    "SegmentMotion",
    "TaskCheck",
    "TaskMotion",
    "ToolLine",
    "ToolPose",
    "Wait",
    "check_task",
    "hold_orientation",
    "joint_line",
    "line_deviation",
    "orientation_deviation",
    "plan_free",
    "plan_line",
    "plan_task",
    "record_problems",
    "segment_name",
    "task_record",
]
