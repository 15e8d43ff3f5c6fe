"""A scene file's ``task:`` to the segments of :mod:`planning.task` and back (docs/formats.md).

The schema of ``task:`` is :mod:`planning.io.task_entry`'s, which reading any scene file needs;
the segments it becomes are built here, where a scene has a task.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import cpr_kin as ck
from planning.errors import SceneError
from planning.io.shape_entry import obstacle_of, payload_to_dict
from planning.io.target_entry import target_entry
from planning.io.task_entry import TaskStepSpec
from planning.task.segments import Attach, Detach, Move, Segment, Wait, segment_name


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
