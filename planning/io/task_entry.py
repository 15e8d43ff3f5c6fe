"""A scene file's ``task:``, to and from the segments of :mod:`planning.task` (docs/formats.md).

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
checked here, in order: a detach of nothing, an attach while carrying, a detach naming
another object are the file's errors.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pinocchio as pin
from pydantic import AfterValidator, BaseModel, Field, model_validator

import cpr_kin as ck
from planning.errors import SceneError
from planning.io.schema_types import Name, Point, Strict, Turn, between
from planning.io.shape_entry import PayloadSpec, obstacle_of, payload_to_dict
from planning.io.target_entry import PoseSpec, TargetSpec, target_entry
from planning.task.orientation import UPRIGHT_RAD, OrientationConstraint
from planning.task.segments import LONGEST_WAIT_S, Attach, Detach, Move, Segment, Wait, segment_name
from planning.task.tool_line import (
    COARSEST_ANGLE_RAD,
    COARSEST_POSITION_M,
    FASTEST_TOOL_M_S,
    FINEST_ANGLE_RAD,
    FINEST_POSITION_M,
    SHORTEST_LINE_M,
    LineTolerance,
    ToolLine,
    ToolPose,
)
from planning.validation import unit_quaternion

MAX_TASK_SEGMENTS = 200
"""Most segments of a task."""
_DEFAULT_TOLERANCE = LineTolerance()


class LineToleranceSpec(Strict):
    """``{position_m, angle_rad}``: the deviation a line allows at every instant [m, rad]."""

    position_m: Annotated[float, between(FINEST_POSITION_M, COARSEST_POSITION_M)] = (
        _DEFAULT_TOLERANCE.position_m
    )
    angle_rad: Annotated[float, between(FINEST_ANGLE_RAD, COARSEST_ANGLE_RAD)] = _DEFAULT_TOLERANCE.angle_rad


class LineSpec(Strict):
    """``line:``: ``to`` a pose or ``by`` an offset (module docstring)."""

    to: PoseSpec | None = None
    by: Point | None = None
    frame: Literal["tool", "base"] = "tool"
    tool_frame: Name | None = None
    tolerance: LineToleranceSpec = Field(default_factory=LineToleranceSpec)
    tool_speed_m_s: Annotated[float, Field(gt=0, le=FASTEST_TOOL_M_S)] | None = None

    @model_validator(mode="after")
    def _one_end(self) -> LineSpec:
        if (self.to is None) == (self.by is None):
            raise ValueError(
                "give exactly one of 'to' (a pose {xyz, quat_xyzw}) or 'by' (an offset [x, y, z] [m])"
            )
        if self.by is not None and float(np.linalg.norm(self.by)) < SHORTEST_LINE_M:
            raise ValueError(
                f"by = {self.by} m is a line of zero length (it keeps the orientation); it must move at "
                f"least {SHORTEST_LINE_M:g} m"
            )
        if self.to is not None and "frame" in self.model_fields_set:
            raise ValueError(
                "'frame' is the frame of 'by'; a line 'to' a pose has its pose in the base frame"
            )
        return self

    def line(self) -> ToolLine:
        """The :class:`~planning.task.tool_line.ToolLine`."""
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
    angle_rad: Annotated[float, between(FINEST_ANGLE_RAD, COARSEST_ANGLE_RAD)] = UPRIGHT_RAD
    quat_xyzw: Quaternion | None = None
    rpy: Turn | None = None
    frame: Name | None = None

    @model_validator(mode="after")
    def _one_reference(self) -> ConstraintSpec:
        if self.quat_xyzw is not None and self.rpy is not None:
            raise ValueError("give at most one of 'quat_xyzw' and 'rpy' (neither: the tool's at the start)")
        if len(set(self.axes)) != len(self.axes):
            raise ValueError(f"axes = {self.axes} names an axis twice; give two or three different axes")
        return self

    def constraint(self) -> OrientationConstraint:
        """The :class:`~planning.task.orientation.OrientationConstraint`."""
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
    wait: Annotated[float, Field(gt=0, le=LONGEST_WAIT_S)] | None = None
    attach: PayloadSpec | None = None
    detach: DetachSpec | None = None

    @model_validator(mode="after")
    def _one_key(self) -> TaskStepSpec:
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


def task_segments(
    steps: Sequence[TaskStepSpec], held: ck.Payload | None, base: Path, source: str
) -> tuple[Segment, ...]:
    """The segments of a validated ``task:``; what the robot carries checked in order from ``held``.

    Raises:
        SceneError: an attach while carrying, a detach of nothing or of another object, a
            payload that is not physical, naming ``task[i].key``.
    """
    segments: list[Segment] = []
    for index, step in enumerate(steps):
        segment = _segment(step, base, f"{source}: task[{index}]")
        where = f"{source}: task[{index}].{segment_name(segment)}"
        if isinstance(segment, Attach):
            if held is not None:
                raise SceneError(f"{where}: the robot already carries '{held.name}' here; detach it first")
            held = segment.payload
        elif isinstance(segment, Detach):
            if held is None:
                raise SceneError(f"{where}: the robot carries nothing here; attach a payload first")
            if segment.name is not None and segment.name != held.name:
                raise SceneError(f"{where}.name = {segment.name!r}, but the robot carries {held.name!r} here")
            held = None
        segments.append(segment)
    return tuple(segments)


def _segment(step: TaskStepSpec, base: Path, where: str) -> Segment:
    if step.move is not None:
        constraint = None if step.move.constraint is None else step.move.constraint.constraint()
        return Move(step.move.target(), constraint)
    if step.line is not None:
        return step.line.line()
    if step.wait is not None:
        return Wait(step.wait)
    if step.attach is not None:
        shape = step.attach.shape
        try:
            payload = step.attach.payload(None if shape is None else obstacle_of(shape, "payload", base))
        except ck.CprKinError as exc:
            raise SceneError(f"{where}.attach: {exc}") from None
        return Attach(payload)
    assert step.detach is not None  # exactly one key (validator)
    return Detach(step.detach.name)


def task_entries(segments: Sequence[Segment]) -> list[dict[str, Any]]:
    """``task:`` in the scene file's form (the inverse of :func:`task_segments`)."""
    return [{segment_name(s): _entry(s)} for s in segments]


def _entry(segment: Segment) -> Any:
    if isinstance(segment, Move):
        if segment.constraint is None:
            return target_entry(segment.goal)
        held = segment.constraint
        constraint: dict[str, Any] = {"axes": list(held.axes), "angle_rad": held.angle_rad}
        if held.quat_xyzw is not None:
            constraint["quat_xyzw"] = list(held.quat_xyzw)
        if held.frame is not None:
            constraint["frame"] = held.frame
        return {**target_entry(segment.goal), "constraint": constraint}
    if isinstance(segment, Wait):
        return segment.seconds
    if isinstance(segment, Attach):
        return payload_to_dict(segment.payload)
    if isinstance(segment, Detach):
        return {} if segment.name is None else {"name": segment.name}
    entry: dict[str, Any] = {}
    if segment.to is not None:
        entry["to"] = {"xyz": list(segment.to.xyz), "quat_xyzw": list(segment.to.quat_xyzw)}
    else:
        entry |= {"by": list(segment.by or ()), "frame": segment.offset_frame}
    if segment.frame is not None:
        entry["tool_frame"] = segment.frame
    entry["tolerance"] = {
        "position_m": segment.tolerance.position_m,
        "angle_rad": segment.tolerance.angle_rad,
    }
    if segment.tool_speed_m_s is not None:
        entry["tool_speed_m_s"] = segment.tool_speed_m_s
    return entry
