"""What a task promised, as plain JSON types, and a check of those promises from the record alone.

:func:`task_record` gives one entry per segment in time order, the layout issue 71 fixes for
the trajectory file's ``task`` list: ``kind`` (``free``, ``line``, ``wait``, ``attach``,
``detach``), ``t0`` and ``t1`` [s]; a ``line`` also ``frame`` (the tool frame), ``from`` and
``to`` (each ``{xyz, quat_xyzw}`` in the robot's base frame) and ``tolerance:
{position_m, angle_rad}``; a free motion under an orientation constraint ``constraint:
{frame, quat_xyzw, axes, angle_rad}``; an ``attach`` or ``detach`` the object's ``object``
name and ``frame``; a segment that moves or waits also ``certified_step`` [m], the step its
verification was certified at (``cpr-plan check`` tries it first).

:func:`record_problems` checks a trajectory against such a list without the planner: the
entries tile the trajectory in time, a ``wait`` stands still, and over each ``line`` the
tool stays within its tolerance at every instant (:func:`~planning.task.line_deviation.line_deviation`'s
certified bound on the line the entry names), and under a ``constraint`` the frame keeps it
(:func:`~planning.task.orientation.orientation_deviation`'s certified bound).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.common.names import shown
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.task.line_deviation import line_deviation
from planning.task.orientation import OrientationConstraint, orientation_deviation
from planning.task.task_plan import TaskMotion
from planning.task.tool_line import LineGeometry, LineTolerance, ToolPose

FloatArray = NDArray[np.float64]

TIME_TOLERANCE_S = 1e-9
"""How far entries' times may miss each other or the trajectory's ends [s] (rounding)."""
STILL_TOLERANCE = 1e-9
"""How far a joint may move while the robot waits [rad or m]."""


def task_record(task: TaskMotion) -> list[dict[str, Any]]:
    """The task's promises, one entry per segment (module docstring)."""
    entries = []
    for segment in task.segments:
        entry: dict[str, Any] = {"kind": segment.kind, "t0": segment.t0, "t1": segment.t1}
        if segment.line is not None:
            line = segment.line
            entry |= {
                "frame": line.frame,
                "from": _pose(line.start),
                "to": _pose(line.goal),
                "tolerance": {
                    "position_m": line.line.tolerance.position_m,
                    "angle_rad": line.line.tolerance.angle_rad,
                },
            }
        if segment.held is not None:
            entry["constraint"] = constraint_entry(segment.held.constraint, segment.held.frame)
        if segment.payload is not None:
            frame = segment.payload.frame_on(task.world.robot)
            entry |= {"object": segment.payload.name, "frame": frame}
        if segment.verification is not None:
            entry["certified_step"] = segment.verification.check.step_m
        entries.append(entry)
    return entries


def constraint_entry(constraint: OrientationConstraint, frame: str) -> dict[str, Any]:
    """A resolved orientation constraint as the record holds it: ``{frame, quat_xyzw, axes, angle_rad}``."""
    assert constraint.quat_xyzw is not None  # resolved where it was planned
    return {
        "frame": frame,
        "quat_xyzw": list(constraint.quat_xyzw),
        "axes": list(constraint.axes),
        "angle_rad": constraint.angle_rad,
    }


def _pose(pose: ToolPose) -> dict[str, list[float]]:
    return {"xyz": list(pose.xyz), "quat_xyzw": list(pose.quat_xyzw)}


def record_problems(
    robot: ck.Robot, trajectory: Trajectory, entries: Sequence[Mapping[str, Any]]
) -> tuple[str, ...]:
    """Each broken promise of ``entries`` by ``trajectory``, in words (empty: every one kept).

    Raises:
        PlanningError: an entry that is not one (a missing or wrong field, named).
    """
    problems = []
    end = float(trajectory.knots[0])
    for index, entry in enumerate(entries):
        kind = _field(entry, "kind", index)
        t0, t1 = _seconds(entry, "t0", index), _seconds(entry, "t1", index)
        if abs(t0 - end) > TIME_TOLERANCE_S or t1 < t0:
            problems.append(
                f"task entry {index} ({kind}) runs [{t0:g}, {t1:g}] s after the last ended at {end:g} s"
            )
        end = t1
        if kind == "wait":
            held = trajectory(np.linspace(t0, t1, 64))
            if np.abs(held - held[0]).max() > STILL_TOLERANCE:
                problems.append(f"task entry {index} (wait) moves during [{t0:g}, {t1:g}] s")
        elif kind == "line":
            problems += _line_problems(robot, trajectory, entry, index, (t0, t1))
        if "constraint" in entry:
            problems += _constraint_problems(robot, trajectory, entry, index, (t0, t1))
    if abs(end - float(trajectory.knots[-1])) > TIME_TOLERANCE_S:
        problems.append(
            f"the task's entries end at {end:g} s, the trajectory at {float(trajectory.knots[-1]):g} s"
        )
    return tuple(problems)


def _line_problems(
    robot: ck.Robot, trajectory: Trajectory, entry: Mapping[str, Any], index: int, span: tuple[float, float]
) -> list[str]:
    """The line's promise over ``span`` [s]: the certified deviation within the tolerance."""
    start, goal = (
        recorded_pose(_field(entry, key, index), f"task entry {index} {key}") for key in ("from", "to")
    )
    tolerance = _field(entry, "tolerance", index)
    limit = LineTolerance(float(tolerance["position_m"]), float(tolerance["angle_rad"]))
    piece = trajectory.between(*span)
    deviation = line_deviation(
        robot, str(_field(entry, "frame", index)), LineGeometry(start, goal), piece, limit
    )
    if deviation.within(limit):
        return []
    return [
        f"task entry {index} (line) leaves its line by {deviation.position_m:.3g} m and "
        f"{deviation.angle_rad:.3g} rad (certified; tolerance {limit.position_m:g} m, "
        f"{limit.angle_rad:g} rad)"
    ]


def _constraint_problems(
    robot: ck.Robot, trajectory: Trajectory, entry: Mapping[str, Any], index: int, span: tuple[float, float]
) -> list[str]:
    """The orientation constraint's promise over ``span`` [s]: its certified angle within the allowed one."""
    constraint, frame = recorded_constraint(entry["constraint"], f"task entry {index} constraint")
    reference = constraint.reference()
    deviation = orientation_deviation(robot, frame, constraint, reference, trajectory.between(*span))
    if deviation.angle_rad <= constraint.angle_rad:
        return []
    return [
        f"task entry {index} ({entry['kind']}) turns '{frame}' {deviation.angle_rad:.3g} rad from its "
        f"constraint about {list(constraint.axes)} (certified; allowed {constraint.angle_rad:g} rad)"
    ]


def _field(entry: Mapping[str, Any], key: str, index: int) -> Any:
    if not isinstance(entry, Mapping) or key not in entry:
        raise PlanningError(
            f"task entry {index} has no '{key}'; an entry has kind, t0, t1 "
            "(a line also frame, from, to, tolerance)"
        )
    return entry[key]


def _seconds(entry: Mapping[str, Any], key: str, index: int) -> float:
    """An entry's time ``key`` [s]: a finite number, else the entry's error naming the value."""
    value = _field(entry, key, index)
    if isinstance(value, bool) or not isinstance(value, int | float) or not np.isfinite(value):
        raise PlanningError(f"task entry {index} '{key}' = {shown(value)}; it must be a finite time [s]")
    return float(value)


def recorded_constraint(given: Any, where: str) -> tuple[OrientationConstraint, str]:
    """A record's ``constraint`` entry as the constraint it names, and its frame.

    Raises:
        PlanningError: not ``{frame, quat_xyzw, axes, angle_rad}`` of valid values, named by ``where``.
    """
    try:
        axes, angle, quat = tuple(given["axes"]), float(given["angle_rad"]), tuple(given["quat_xyzw"])
        return OrientationConstraint(axes, angle, quat), str(given["frame"])
    except (KeyError, TypeError, ValueError, PlanningError) as exc:
        raise PlanningError(f"{where}: expected {{frame, quat_xyzw, axes, angle_rad}} ({exc})") from None


def recorded_pose(pose: Any, where: str) -> pin.SE3:
    """A record's ``{xyz, quat_xyzw}`` as a placement.

    Raises:
        PlanningError: not such a pose, named by ``where``.
    """
    try:
        return ToolPose(tuple(pose["xyz"]), tuple(pose["quat_xyzw"])).placement()
    except (KeyError, TypeError) as exc:
        raise PlanningError(
            f"{where}: expected {{xyz: [x, y, z], quat_xyzw: [x, y, z, w]}} ({exc})"
        ) from None
