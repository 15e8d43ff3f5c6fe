"""A scene file's ``task:``: its schema, checked against :mod:`planning.task.limits` (docs/formats.md).

```yaml
task:                       # in order; each entry has exactly one key
  - move: {tcp: [0.4, 0.2, 0.3]}                      # a free motion to a start's or goal's target
  - move: {pose: {xyz: [0.4, 0.2, 0.3], rpy: [3.1416, 0, 0]},
           constraint: {axes: [x, y], angle_rad: 0.0873}}   # the tool kept upright on the way
  - line: {by: [0, 0, -0.08], frame: base}            # a straight tool line by an offset [m]
  - wait: 0.5                                         # standing still [s]
  - attach: {name: part, mass_kg: 1.5, shape: {shape: box, size: [0.04, 0.04, 0.04], xyz: [0, 0, 0.03]},
             touch_links: [tool_link]}                # a payload's keys
  - line: {to: {xyz: [0.4, 0.2, 0.3], quat_xyzw: [1, 0, 0, 0]}, tolerance: {position_m: 0.001}}
  - detach: {name: part}                              # or {}: whatever it carries
```

A line's ``frame`` is the frame ``by`` is given in (``tool``: the tool's axes at the line's
start, the default; ``base``); ``tool_frame`` the frame held on the line (default: the
robot's tool frame); ``tool_speed_m_s`` a limit on its speed. What the robot carries is
checked in order where the segments are built (:mod:`planning.io.task_segments`): a detach of
nothing, an attach while carrying, a detach naming another object are the file's errors.
"""

from typing import TYPE_CHECKING, Annotated, Literal, Self

import numpy as np
import pinocchio as pin
from pydantic import AfterValidator, BaseModel, Field, model_validator

from planning.io.schema_types import Name, Point, Strict, Turn, between
from planning.io.shape_entry import PayloadSpec
from planning.io.target_entry import PoseSpec, TargetSpec
from planning.task import limits
from planning.validation import unit_quaternion

if TYPE_CHECKING:  # the classes, imported where a spec becomes one (reading a scene needs only the bounds)
    from planning.task.orientation import OrientationConstraint
    from planning.task.tool_line import ToolLine

MAX_TASK_SEGMENTS = 200
"""Most segments of a task."""


PositionTolerance = Annotated[float, between(limits.FINEST_POSITION_M, limits.COARSEST_POSITION_M)]
"""How far a line's tool may leave it [m]."""
AngleTolerance = Annotated[float, between(limits.FINEST_ANGLE_RAD, limits.COARSEST_ANGLE_RAD)]
"""How far a line's or a constraint's tool may turn from its orientation [rad]."""


class LineToleranceSpec(Strict):
    """``{position_m, angle_rad}``: the deviation a line allows at every instant [m, rad]."""

    position_m: PositionTolerance = limits.LINE_POSITION_M
    angle_rad: AngleTolerance = limits.LINE_ANGLE_RAD


class LineSpec(Strict):
    """``line:``: ``to`` a pose or ``by`` an offset (module docstring)."""

    to: PoseSpec | None = None
    by: Point | None = None
    frame: Literal["tool", "base"] = "tool"
    tool_frame: Name | None = None
    tolerance: LineToleranceSpec = Field(default_factory=LineToleranceSpec)
    tool_speed_m_s: Annotated[float, Field(gt=0, le=limits.FASTEST_TOOL_M_S)] | None = None

    @model_validator(mode="after")
    def _one_end(self) -> Self:
        if (self.to is None) == (self.by is None):
            raise ValueError(
                "give exactly one of 'to' (a pose {xyz, quat_xyzw}) or 'by' (an offset [x, y, z] [m])"
            )
        if self.by is not None and float(np.linalg.norm(self.by)) < limits.SHORTEST_LINE_M:
            raise ValueError(
                f"by = {self.by} m is a line of zero length (it keeps the orientation); it must move at "
                f"least {limits.SHORTEST_LINE_M:g} m"
            )
        if self.to is not None and "frame" in self.model_fields_set:
            raise ValueError(
                "'frame' is the frame of 'by'; a line 'to' a pose has its pose in the base frame"
            )
        return self

    def line(self) -> "ToolLine":
        """The :class:`~planning.task.tool_line.ToolLine`."""
        from planning.task.tool_line import LineTolerance, ToolLine, ToolPose

        to = None
        if self.to is not None:
            to = ToolPose.of(pin.SE3(self.to.rotation(), np.array(self.to.xyz)))
        return ToolLine(
            frame=self.tool_frame,
            to=to,
            by=None if self.by is None else (self.by[0], self.by[1], self.by[2]),
            offset_frame=self.frame,
            tolerance=LineTolerance(self.tolerance.position_m, self.tolerance.angle_rad),
            tool_speed_m_s=self.tool_speed_m_s,
        )


Axis = Literal["x", "y", "z"]


def _upright() -> list[Axis]:
    return ["x", "y"]


Quaternion = Annotated[
    list[Annotated[float, Field(allow_inf_nan=False)]],
    Field(min_length=4, max_length=4),
    AfterValidator(lambda xyzw: list(unit_quaternion(xyzw))),
]


class ConstraintSpec(Strict):
    """``constraint:`` of a ``move``: the tool's orientation held about ``axes`` within ``angle_rad``."""

    axes: Annotated[list[Axis], Field(min_length=2, max_length=3)] = Field(default_factory=_upright)
    angle_rad: AngleTolerance = limits.UPRIGHT_RAD
    quat_xyzw: Quaternion | None = None
    rpy: Turn | None = None
    frame: Name | None = None

    @model_validator(mode="after")
    def _one_reference(self) -> Self:
        if self.quat_xyzw is not None and self.rpy is not None:
            raise ValueError("give at most one of 'quat_xyzw' and 'rpy' (neither: the tool's at the start)")
        if len(set(self.axes)) != len(self.axes):
            raise ValueError(f"axes = {self.axes} names an axis twice; give two or three different axes")
        return self

    def constraint(self) -> "OrientationConstraint":
        """The :class:`~planning.task.orientation.OrientationConstraint`."""
        from planning.task.orientation import OrientationConstraint
        from planning.task.tool_line import ToolPose

        quat = None
        if self.quat_xyzw is not None:
            quat = (self.quat_xyzw[0], self.quat_xyzw[1], self.quat_xyzw[2], self.quat_xyzw[3])
        elif self.rpy is not None:
            quat = ToolPose.of(pin.SE3(pin.rpy.rpyToMatrix(*self.rpy), np.zeros(3))).quat_xyzw
        return OrientationConstraint(tuple(self.axes), self.angle_rad, quat, self.frame)


class MoveSpec(TargetSpec):
    """``move:``: a goal's keys, and an optional orientation ``constraint``."""

    constraint: ConstraintSpec | None = None


class DetachSpec(Strict):
    """``detach: {}`` or ``detach: {name: NAME}`` (the object released, checked)."""

    name: Name | None = None


class TaskStepSpec(Strict):
    """One entry of ``task:``: exactly one of its keys."""

    move: MoveSpec | None = None
    line: LineSpec | None = None
    wait: Annotated[float, Field(gt=0, le=limits.LONGEST_WAIT_S)] | None = None
    attach: PayloadSpec | None = None
    detach: DetachSpec | None = None

    @model_validator(mode="after")
    def _one_key(self) -> Self:
        given = [key for key in type(self).model_fields if getattr(self, key) is not None]
        if len(given) != 1:
            raise ValueError(f"an entry of task has exactly one key of {list(type(self).model_fields)}")
        return self


TaskSpec = Annotated[list[TaskStepSpec], Field(min_length=1, max_length=MAX_TASK_SEGMENTS)]

_STEP_MODELS: dict[str, type[BaseModel]] = {
    "move": MoveSpec,
    "line": LineSpec,
    "attach": PayloadSpec,
    "detach": DetachSpec,
}


def task_model_at(location: tuple[int | str, ...]) -> type[BaseModel] | None:
    """The model owning the key at ``location`` below ``task`` (``(2, "line", "by")``), to list its keys."""
    if len(location) <= 2:
        return TaskStepSpec
    if location[1:3] == ("line", "tolerance"):
        return LineToleranceSpec
    if location[1:3] in (("line", "to"), ("move", "pose")):
        return PoseSpec
    if location[1:3] == ("move", "constraint"):
        return ConstraintSpec
    return _STEP_MODELS.get(str(location[1]))
