"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .line_deviation import LineDeviation, line_deviation
from .line_ik import JointLine, joint_line
from .line_motion import LineMotion, plan_line
from .task_plan import Attach, Detach, Move, SegmentMotion, TaskMotion, Wait, plan_task
from .task_record import record_problems, task_record
from .tool_line import LineGeometry, LineTolerance, ToolLine, ToolPose

__all__ = [
    "Attach",
    "Detach",
    "JointLine",
    "LineDeviation",
    "LineGeometry",
    "LineMotion",
    "LineTolerance",
    "Move",
    "SegmentMotion",
    "TaskMotion",
    "ToolLine",
    "ToolPose",
    "Wait",
    "joint_line",
    "line_deviation",
    "plan_line",
    "plan_task",
    "record_problems",
    "task_record",
]
