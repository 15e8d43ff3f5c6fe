"""A task: free motions, tool lines and waits, planned one after the other into one trajectory.

:func:`plan_task` starts at the scene's start and plans each segment from where the one
before ends: a :class:`Move` by the planner's search (to a joint, ``tcp`` or pose goal, the
scene's obstacles, margins and payload), a :class:`~planning.task.tool_line.ToolLine` by
:func:`~planning.task.line_motion.plan_line`, a :class:`Wait` standing still. Each is planned
from rest to rest; then motions that follow each other without a wait, an attach or a detach
are joined into one path and timed as one where that is sooner than stopping between them, so
that the robot stops where the task says and where a stop is sooner
(:mod:`planning.task.task_timing`). The whole is C3 and each segment verified as every
trajectory of the planner is. The scene's own goal is neither planned to nor needed: the
segments say where the robot goes.

:class:`Attach` and :class:`Detach` change what the robot carries from there on: its mass in
the torques, its shape in the clearance checks, the links it may touch; an attach may take an
obstacle from the world and a detach leaves the object in it (:mod:`planning.task.holding`). A scene file's
``task:`` holds the same segments (:mod:`planning.io.task_entry`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.continuity import discontinuity
from planning.curves.stop_and_go import joined
from planning.curves.trajectory import Trajectory
from planning.errors import NoSolutionError, PlanningError, TaskSegmentError, ToolLineBrokenError
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.pipeline.verification import Requirements, Verification
from planning.task.free_motion import FIXED_DURATION, plan_free
from planning.task.held_orientation import HeldMotion
from planning.task.holding import changed_object, checked_touches, scene_after, untaken
from planning.task.line_goal import LineWalks, line_after
from planning.task.line_motion import LineMotion, plan_line
from planning.task.segments import KINDS, Attach, Detach, Move, Segment, Wait, segment_name
from planning.task.task_timing import PlannedMotion, timed_motions
from planning.task.tool_line import ToolLine

if TYPE_CHECKING:
    from planning.search.firefly import FireflyProgress

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class SegmentMotion:
    """One segment of a planned task.

    Attributes:
        kind: ``free``, ``line``, ``wait``, ``attach`` or ``detach``.
        t0: when it starts in the task's trajectory [s].
        t1: when it ends [s] (an attach or detach takes no time).
        verification: its trajectory's verification with what the robot carries then
            (``None`` for an attach or detach, which does not move).
        line: the planned line, for a ``line``.
        payload: the object attached, for an ``attach``; released, for a ``detach``.
        held: the motion that keeps an orientation constraint, for a ``free`` one under one.
        world: the world its trajectory was verified in: the robot with what it carries then,
            among the obstacles then (``None`` for an attach or detach).
    """

    kind: str
    t0: float
    t1: float
    verification: Verification | None = None
    line: LineMotion | None = None
    payload: ck.Payload | None = None
    held: HeldMotion | None = None
    world: ck.CollisionWorld | None = field(default=None, repr=False)


@dataclass(frozen=True)
class TaskMotion:
    """A planned task (:func:`plan_task`).

    Attributes:
        segments: each segment's kind, times and verification, in order.
        trajectory: the whole motion, at rest at its ends, its waits, attaches and detaches.
        continuity: where the whole is not C3 (``None``: it is, at every knot).
        world: the robot among the scene's obstacles, carrying what it carries at the start
            (for drawing: without the obstacles the task takes, drawn as what it carries).
        scene: the scene planned in (its start, obstacles, margins, payload at the start).
        task: the segments asked for, in order (``segments`` says how each was planned).
    """

    segments: tuple[SegmentMotion, ...]
    trajectory: Trajectory
    continuity: str | None
    world: ck.CollisionWorld = field(repr=False)
    scene: Scene = field(repr=False)
    task: tuple[Segment, ...] = ()

    @property
    def margin_m(self) -> float:
        """The scene's safety margin [m]."""
        return self.scene.safety_margin

    @property
    def junctions(self) -> FloatArray:
        """``(k, nq)`` the configurations where the segments meet, the start and end included."""
        times = sorted({0.0, *(s.t1 for s in self.segments)})
        return np.asarray(self.trajectory(np.array(times)))

    @property
    def problems(self) -> tuple[str, ...]:
        """Every failed condition, each with its segment (empty when accepted)."""
        found = [] if self.continuity is None else [self.continuity]
        for index, segment in enumerate(self.segments):
            if segment.verification is not None:
                found += [f"segment {index} ({segment.kind}) {p}" for p in segment.verification.problems]
        return tuple(found)

    @property
    def accepted(self) -> bool:
        """Every segment passes its verification and the whole is C3."""
        return not self.problems

    def verified(self) -> TaskMotion:
        """The task, where it is :attr:`accepted` (what is written and reported).

        Raises:
            NoSolutionError: it is not (each segment was verified as planned: a failure here
                is a bug's), naming every problem.
        """
        if not self.accepted:
            raise NoSolutionError("the planned task fails its verification: " + "; ".join(self.problems))
        return self

    @property
    def certified_min_clearance_m(self) -> float:
        """The least certified clearance from the obstacles over the whole motion [m]."""
        return min(s.verification.check.certified_min_m for s in self.segments if s.verification is not None)


@dataclass(frozen=True)
class _Carrying:
    """The scene as the robot meets it while it carries what it carries (at ``q``)."""

    scene: Scene
    problem: Problem
    required: Requirements

    @property
    def threads(self) -> int:
        """The threads of its parallel collision checks, for the next segment's problems."""
        return self.problem.world.num_threads


def plan_task(
    scene: Scene,
    segments: Sequence[Segment],
    robot: ck.Robot | None = None,
    progress: Callable[[FireflyProgress], None] | None = None,
    threads: int | None = None,
) -> TaskMotion:
    """The task's ``segments`` planned from the scene's start, joined and verified.

    Each segment is verified with what the robot carries during it (the scene's payload at
    the start, then what :class:`Attach` and :class:`Detach` say); the whole must be C3.
    ``progress`` is called after each iteration of each free motion's search; ``threads``
    are those of the parallel collision checks (default: one on 2 cores, two on more; a batch
    runs tasks in parallel, not the checks of one).

    Raises:
        PlanningError: no segment, a bad segment, or a segment's bad input (a goal inside a
            margin, a line of zero length, a detach of nothing), naming the segment.
        TaskSegmentError: a segment has no solution (a ``NoSolutionError``: exit 3), naming
            it, with its own error as ``cause`` (a free motion not found; a line that breaks,
            with its ``fraction``).
    """
    if not segments:
        raise PlanningError("a task needs at least one segment (a Move, a ToolLine, a Wait, an Attach)")
    if scene.duration is not None:
        raise PlanningError(FIXED_DURATION.format(seconds=scene.duration))
    checked_touches(scene, segments)
    base = robot or ck.shared_robot(scene.robot_spec())
    carrying = _carrying(scene, base, None, threads)
    q, start_world = carrying.problem.q_start, carrying.problem.world
    kinds, payloads, planned = [], [], list[PlannedMotion | None]()
    goal_tests: dict[int, LineWalks] = {}  # a move's goal test, by the index of the line after it
    for index, segment in enumerate(segments):
        kinds.append(KINDS.get(type(segment), type(segment).__name__))
        try:
            if isinstance(segment, Attach | Detach):
                before = carrying.scene
                carrying = _carried(carrying, base, q, segment)
                payloads.append(changed_object(segment, before, carrying.scene))
                planned.append(None)
                continue
            goal_test = None
            if isinstance(segment, Move) and (line := line_after(segments, index)) is not None:
                next_line = segments[line]
                assert isinstance(next_line, ToolLine)  # what line_after finds
                goal_test = goal_tests[line] = LineWalks(carrying.problem.world, next_line, carrying.required)
            motion = _planned(carrying, base, q, segment, progress, goal_test)
        except (PlanningError, ck.CprKinError) as exc:
            raise PlanningError(f"task[{index}] ({segment_name(segment)}): {exc}") from exc
        except NoSolutionError as exc:
            if isinstance(exc, ToolLineBrokenError) and index in goal_tests:
                exc = goal_tests[index].from_no_goal(exc)
            raise TaskSegmentError(index, segment_name(segment), exc) from exc
        payloads.append(None)
        planned.append(motion)
        q = motion.trajectory(motion.trajectory.knots[-1])
    if all(motion is None for motion in planned):
        raise PlanningError("a task needs a segment that moves or waits, not only attach and detach")
    records, pieces, now = [], [], 0.0
    timed_ones = timed_motions(planned, base)
    for kind, payload, source, timed in zip(kinds, payloads, planned, timed_ones, strict=True):
        if source is None or timed is None:
            records.append(SegmentMotion(kind, now, now, payload=payload))
            continue
        end = now + timed.trajectory.duration
        world = source.problem.world
        records.append(
            SegmentMotion(kind, now, end, timed.verification, timed.line, held=timed.held, world=world)
        )
        pieces.append(timed.trajectory)
        now = end
    whole = joined(pieces)
    arm = carrying.problem.robot  # the robot as planned (its payload attached)
    continuity = discontinuity(whole, arm.joint_names, arm.joint_units)
    drawn = untaken(start_world.obstacles, payloads)
    if len(drawn) < len(start_world.obstacles):  # the task takes some: drawn as what it carries
        start_world = ck.CollisionWorld(start_world.robot, drawn, num_threads=start_world.num_threads)
    return TaskMotion(tuple(records), whole, continuity, start_world, scene, tuple(segments))


def _carrying(scene: Scene, base: ck.Robot, q: FloatArray | None, threads: int | None) -> _Carrying:
    """The scene at ``q`` (``None``: its start) with its payload, checked as a scene's start is.

    ``threads``: those of its checks (:func:`~planning.pipeline.problem.build_problem`).
    """
    start = scene.start if q is None else Target(q=tuple(q.tolist()))
    at = dataclasses.replace(scene, start=start, goal=start)  # its goal: not the task's
    problem = build_problem(at, base, threads)
    return _Carrying(at, problem, Requirements.of(problem))


def _carried(carrying: _Carrying, base: ck.Robot, q: FloatArray, segment: Attach | Detach) -> _Carrying:
    """What it carries after ``segment``, the world it leaves (:func:`scene_after`), checked at ``q``."""
    return _carrying(scene_after(carrying.scene, base, q, segment), base, q, carrying.threads)


def _planned(
    carrying: _Carrying,
    base: ck.Robot,
    q: FloatArray,
    segment: Segment,
    progress: Callable[[FireflyProgress], None] | None,
    goal_test: Callable[[FloatArray], bool] | None = None,
) -> PlannedMotion:
    """One segment from ``q``: a line, a wait, a free motion (bent onto its constraint if it has one).

    ``goal_test``: a free motion's goal test (:func:`~planning.task.free_motion.plan_free`; the
    line after it walks from there).
    """
    required = carrying.required
    if isinstance(segment, ToolLine):
        line = plan_line(carrying.problem.world, q, segment, required)
        return PlannedMotion(line.trajectory, carrying.problem, required, line=line)
    if isinstance(segment, Wait):
        coefficients = np.zeros((1, len(q), 8))
        coefficients[0, :, 0] = q
        still = Trajectory(np.array([0.0, segment.seconds]), coefficients)
        return PlannedMotion(still, carrying.problem, required, still=True)
    if isinstance(segment, Move):
        scene = dataclasses.replace(carrying.scene, start=Target(q=tuple(q.tolist())), goal=segment.goal)
        free = plan_free(scene, base, segment.constraint, required, progress, carrying.threads, goal_test)
        return PlannedMotion(free.trajectory, free.problem, required, held=free.held)
    raise PlanningError(
        f"a task segment is a Move, a ToolLine, a Wait, an Attach or a Detach, not a {type(segment).__name__}"
    )
