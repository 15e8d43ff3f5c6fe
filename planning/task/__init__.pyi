"""Type stub of the package: what it exports, and from which module (read by ``lazy_loader``)."""

from .line_deviation import LineDeviation, line_deviation, tool_levers
from .line_ik import JointLine, joint_line
from .line_motion import LineMotion, plan_line
from .tool_line import LineGeometry, LineTolerance, ToolLine, ToolPose

__all__ = [
    "JointLine",
    "LineDeviation",
    "LineGeometry",
    "LineMotion",
    "LineTolerance",
    "ToolLine",
    "ToolPose",
    "joint_line",
    "line_deviation",
    "plan_line",
    "tool_levers",
]
