"""A task's trajectory checked against the task it was planned for: what ``cpr-plan check`` does.

:func:`check_task` holds a trajectory and its record (:func:`~planning.task.task_record.task_record`,
the trajectory file's ``task`` list) to the scene's task:

- the record's segments are the task's, kind by kind, and keep their promises
  (:func:`~planning.task.task_record.record_problems`: they tile the trajectory, a wait stands
  still, a line stays within its tolerance at every instant);
- a line is the task's line: it starts where the tool is at its start and ends where the
  task's line from there ends;
- the trajectory starts at the scene's start, is C3 at every knot, and each free motion ends
  at its goal;
- each segment that moves or waits is verified as every trajectory of the planner is, with
  what the robot carries then and the world as it is then (the scene's payload and obstacles,
  then what ``attach`` and ``detach`` change, :mod:`planning.task.holding`): certified
  clearance, joint ranges and limits, torques.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

import cpr_kin as ck
from planning.curves.continuity import discontinuity
from planning.curves.trajectory import Trajectory
from planning.errors import NoSolutionError, PlanningError
from planning.pipeline.hulls_first import check_steps_m
from planning.pipeline.problem import build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.settings import recorded_step_m
from planning.pipeline.target import Target
from planning.pipeline.verification import Requirements, Verification, verify_finer_where_needed
from planning.task.holding import changed_object, scene_after
from planning.task.segments import KINDS, Attach, Detach, Move, Segment, Wait
from planning.task.task_record import TIME_TOLERANCE_S, record_problems, recorded_constraint, recorded_pose
from planning.task.tool_line import ToolLine

POSE_TOLERANCE = 1e-6
"""How far a recorded line's ends may be from the task's [m, rad] (rounding)."""


@dataclass(frozen=True)
class TaskCheck:
    """A task's trajectory checked (:func:`check_task`).

    Attributes:
        verifications: each segment's verification, ``None`` for an attach or detach (or a
            segment whose ends could not be set up: see :attr:`problems`).
        problems: every broken promise, each naming its segment (empty: all kept).
    """

    verifications: tuple[Verification | None, ...]
    problems: tuple[str, ...]

    @property
    def accepted(self) -> bool:
        """Every promise kept."""
        return not self.problems

    @property
    def certified_min_clearance_m(self) -> float:
        """The least certified clearance from the obstacles over the segments verified [m]."""
        found = [v.check.certified_min_m for v in self.verifications if v is not None]
        return min(found) if found else float("nan")

    @property
    def checks(self) -> int:
        """How many configurations the certified checks measured."""
        return sum(len(v.check.times) for v in self.verifications if v is not None)


def check_task(
    scene: Scene,
    segments: Sequence[Segment],
    trajectory: Trajectory,
    entries: Sequence[Mapping[str, Any]],
    robot: ck.Robot | None = None,
) -> TaskCheck:
    """``trajectory`` and its record ``entries`` held to the task ``segments`` in ``scene`` (see above).

    Raises:
        PlanningError: an entry that is not one (a missing or wrong field, named).
    """
    base = robot or ck.shared_robot(scene.robot_spec())
    kinds = [KINDS[type(s)] for s in segments]
    recorded = [str(e.get("kind")) if isinstance(e, Mapping) else "?" for e in entries]
    if recorded != kinds:
        return TaskCheck((), (f"the trajectory's task is {recorded}; the scene's is {kinds}",))
    problems = list(record_problems(base, trajectory, entries))
    jump = discontinuity(trajectory, base.joint_names, base.joint_units)
    problems += [] if jump is None else [jump]
    miss = scene.start.miss(base, trajectory(trajectory.knots[0]))
    problems += [] if miss is None else [f"its start is {miss} of the scene's start"]
    current, verifications = scene, list[Verification | None]()
    for index, (segment, entry) in enumerate(zip(segments, entries, strict=True)):
        where = f"task[{index}] ({KINDS[type(segment)]})"
        if isinstance(segment, Attach | Detach):
            before = current
            try:
                current = scene_after(current, base, trajectory(float(entry["t0"])), segment)
            except PlanningError as exc:
                problems.append(f"{where} {exc}")
            named = changed_object(segment, before, current)
            problems += [f"{where} {w}" for w in _recorded_object(named, entry)]
            verifications.append(None)
            continue
        span = (float(entry["t0"]), float(entry["t1"]))
        piece = trajectory.between(*span)
        q_start = trajectory(span[0])
        try:
            if isinstance(segment, ToolLine):
                problems += [f"{where} {p}" for p in _line_ends(base, segment, q_start, entry)]
            if isinstance(segment, Move):
                problems += [f"{where} {p}" for p in _constraint_kept(base, segment, q_start, entry)]
            step_m = recorded_step_m(entry.get("certified_step"), "certified_step")
        except PlanningError as exc:
            raise PlanningError(f"task entry {index}: {exc}") from None
        if isinstance(segment, Wait) and abs(span[1] - span[0] - segment.seconds) > TIME_TOLERANCE_S:
            waited = span[1] - span[0]
            problems.append(f"{where} waits {waited:g} s; the task's wait is {segment.seconds:g} s")
        verification, wrong = _verified(current, base, segment, piece, step_m)
        problems += [f"{where} {w}" for w in wrong]
        verifications.append(verification)
    return TaskCheck(tuple(verifications), tuple(problems))


def _recorded_object(named: ck.Payload | None, entry: Mapping[str, Any]) -> list[str]:
    """Where an attach's or detach's record names another object, or another frame, than ``named``."""
    expected = None if named is None else named.name
    wrong = [] if entry.get("object") == expected else [f"names {entry.get('object')!r}, not {expected!r}"]
    frame = None if named is None else named.frame
    if frame is not None and entry.get("frame") != frame:
        wrong.append(f"holds it at frame {entry.get('frame')!r}, not at {frame!r}")
    return wrong


def _line_ends(robot: ck.Robot, line: ToolLine, q_start: np.ndarray, entry: Mapping[str, Any]) -> list[str]:
    """Where the recorded line is not the task's line from ``q_start``: its frame, ends, tolerance."""
    frame = line.frame or robot.tcp_frame
    if entry.get("frame") != frame:
        return [f"holds frame {entry.get('frame')!r} on its line; the task's line holds {frame!r}"]
    pose = ck.frame_poses(robot, q_start, frame)
    start = pin.SE3(pose[:3, :3], pose[:3, 3])
    wrong = []
    for key, wanted in (("from", start), ("to", line.goal(start))):
        given = recorded_pose(entry.get(key), f"'{key}'")
        moved = float(np.linalg.norm(given.translation - wanted.translation))
        turned = float(np.linalg.norm(pin.log3(given.rotation.T @ wanted.rotation)))
        if moved > POSE_TOLERANCE or turned > POSE_TOLERANCE:
            xyz = ", ".join(f"{v:.6g}" for v in wanted.translation)
            wrong.append(
                f"records its '{key}' pose {moved:.3g} m and {turned:.3g} rad from the task's line, "
                f"whose '{key}' is at xyz [{xyz}] m"
            )
    tolerance = entry.get("tolerance")
    asked = {"position_m": line.tolerance.position_m, "angle_rad": line.tolerance.angle_rad}
    if tolerance != asked:
        wrong.append(f"records tolerance {tolerance}; the task's line asks {asked}")
    return wrong


def _constraint_kept(robot: ck.Robot, move: Move, q_start: np.ndarray, entry: Mapping[str, Any]) -> list[str]:
    """Where the recorded constraint is not the task's: absent, present, or another one."""
    recorded, constraint = entry.get("constraint"), move.constraint
    if constraint is None:
        return [] if recorded is None else ["records a constraint; the task's motion has none"]
    if not isinstance(recorded, Mapping):
        return [f"records no constraint; the task's motion keeps {list(constraint.axes)} within the limit"]
    frame = constraint.frame or robot.tcp_frame
    constraint = constraint.about(ck.frame_poses(robot, q_start, frame)[:3, :3])  # none given: the start's
    wrong = []
    asked = {"frame": frame, "axes": list(constraint.axes), "angle_rad": constraint.angle_rad}
    if {key: recorded.get(key) for key in asked} != asked:
        wrong.append(f"records constraint {dict(recorded)}; the task's motion asks {asked}")
    given, _ = recorded_constraint(recorded, "'constraint'")
    turned = float(np.linalg.norm(pin.log3(given.reference().T @ constraint.reference())))
    if turned > POSE_TOLERANCE:
        wrong.append(f"records its constraint's orientation {turned:.3g} rad from the task's")
    return wrong


def _verified(
    scene: Scene, robot: ck.Robot, segment: Segment, piece: Trajectory, step_m: float | None
) -> tuple[Verification | None, list[str]]:
    """``piece`` verified in ``scene`` (with its payload), a free motion's end against its goal.

    Where the scene's steps cannot certify it, the ``step_m`` [m] its entry records is tried
    first, then those the planner may have taken (:func:`~planning.pipeline.hulls_first.check_steps_m`).
    """
    q0, q1 = (tuple(piece(t).tolist()) for t in (piece.knots[0], piece.knots[-1]))
    try:
        problem = build_problem(dataclasses.replace(scene, start=Target(q=q0), goal=Target(q=q1)), robot)
    except (PlanningError, NoSolutionError) as exc:  # an end inside a margin, a load it cannot hold
        return None, [f"cannot be verified from where it starts and ends: {exc}"]
    required = Requirements.of(problem)
    if isinstance(segment, Move):
        required = dataclasses.replace(required, endpoints=(Target(q=q0), segment.goal))
    verification = verify_finer_where_needed(problem, piece, required, check_steps_m(problem, step_m))
    return verification, list(verification.problems)
