"""A task's motions as the robot runs them: joined where the task does not stop, verified segment by segment.

Each segment is planned on its own, from rest to rest (:class:`PlannedMotion`). Where two or
more motions follow each other without a wait, an attach or a detach between them (a run,
:func:`~planning.task.junctions.runs`), they may be joined into one path and timed as one
(:func:`~planning.task.junctions.joined_motion`): the robot passes their junctions without
stopping, where that is sooner than stopping (:func:`_fastest_joins`). A joined motion is cut
at the junctions and each part verified as its segment:
the planner's verification with what the robot carries, a line's deviation certified within
its tolerance (and its tool speed within its limit: the whole run is slowed for it), a
constrained motion's angle within its constraint. Where any part fails, those motions keep
their stops: each segment's own rest-to-rest motion, verified as planned.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.errors import NoSolutionError, PlanningError
from planning.pipeline.problem import Problem
from planning.pipeline.verification import Requirements, Verification, verify_finer_where_needed
from planning.task.held_orientation import HeldMotion
from planning.task.junctions import Piece, joined_motion, runs
from planning.task.line_deviation import line_deviation
from planning.task.line_motion import LineMotion
from planning.task.orientation import orientation_deviation


@dataclass(frozen=True)
class PlannedMotion:
    """A segment that moves or waits, planned on its own from rest to rest.

    Attributes:
        trajectory: its motion from time 0.
        problem: the problem whose finer step may certify it
            (:func:`~planning.pipeline.verification.verify_finer_where_needed`): a free
            motion's own, else the carrying scene's.
        required: what it is verified against (with what the robot carries then).
        line: the planned line, for a line.
        held: the motion under an orientation constraint, for a constrained free motion.
        still: a wait (always a stop).
    """

    trajectory: Trajectory
    problem: Problem
    required: Requirements
    line: LineMotion | None = None
    held: HeldMotion | None = None
    still: bool = False

    @property
    def rigid(self) -> bool:
        """Followed as planned: a line, or a path under a constraint."""
        return self.line is not None or self.held is not None

    @property
    def path(self) -> Trajectory:
        """The geometric path: a line's or a constrained motion's own, a free motion's timed one."""
        if self.line is not None:
            return self.line.path.path
        return self.held.path if self.held is not None else self.trajectory


@dataclass(frozen=True)
class TimedMotion:
    """A segment as the task runs it: its motion, verified, and its line or constrained motion then."""

    trajectory: Trajectory
    verification: Verification
    line: LineMotion | None = None
    held: HeldMotion | None = None


def timed_motions(motions: Sequence[PlannedMotion | None], robot: ck.Robot) -> list[TimedMotion | None]:
    """Each motion as the task runs it (``None`` for an attach or detach; see above)."""
    rigid = [None if m is None or m.still else m.rigid for m in motions]
    timed: list[TimedMotion | None] = [None] * len(motions)
    for run in runs(rigid):
        members = [(index, motion) for index in run if (motion := motions[index]) is not None]
        for first, parts in _fastest_joins(robot, [motion for _, motion in members]):
            for (index, _), part in zip(members[first:], parts, strict=False):
                timed[index] = part
    for index, motion in enumerate(motions):
        if motion is not None and timed[index] is None:
            verification = verify_finer_where_needed(motion.problem, motion.trajectory, motion.required)
            timed[index] = TimedMotion(motion.trajectory, verification, motion.line, motion.held)
    return timed


def _fastest_joins(robot: ck.Robot, run: list[PlannedMotion]) -> list[tuple[int, list[TimedMotion]]]:
    """The parts of ``run`` joined where passing their junctions is faster than stopping at them, verified.

    The robot passes a junction without stopping only where it arrives sooner so: a motion
    that turns back at a junction (a move out and back the same way) stops, turns and goes
    faster than it bends through a hairpin at speed. Of every way to cut the run into
    consecutive parts, each either two or more motions joined and timed as one or one motion
    from rest to rest, the one of the least duration is taken (dynamic programming over the
    cuts, each part timed once; a tie joins). A joined part whose motions fail their
    verification is then ruled out and the choice made again.

    Returns:
        ``(index of its first motion in run, its motions as the task runs them)`` for each
        joined part; the motions of no part stop at both ends, as planned.
    """
    count = len(run)
    own_s = [motion.trajectory.duration for motion in run]
    timings: dict[tuple[int, int], tuple[Trajectory, list[float]] | None] = {}
    verified: dict[tuple[int, int], list[TimedMotion] | None] = {}

    def duration_s(first: int, end: int) -> float:
        if end == first + 1:
            return own_s[first]
        if (first, end) not in timings:
            timings[first, end] = _timed_join(robot, run[first:end])
        timing = timings[first, end]
        if timing is None or verified.get((first, end), True) is None:
            return math.inf
        return timing[1][-1]

    while True:
        least_s, cut = [0.0] + [math.inf] * count, [0] * (count + 1)
        for end in range(1, count + 1):
            for first in range(end):  # the longest part first: a tie joins
                total_s = least_s[first] + duration_s(first, end)
                if total_s < least_s[end]:
                    least_s[end], cut[end] = total_s, first
        parts, end = [], count
        while end:
            parts.append((cut[end], end))
            end = cut[end]
        chosen = []
        for first, end in reversed(parts):
            if end - first < 2:
                continue
            if (first, end) not in verified:
                timing = timings[first, end]  # chosen, so timed
                verified[first, end] = (
                    None if timing is None else _verified_parts(robot, run[first:end], *timing)
                )
            joined = verified[first, end]
            if joined is None:
                break  # ruled out: choose again
            chosen.append((first, joined))
        else:
            return chosen


def _timed_join(robot: ck.Robot, run: list[PlannedMotion]) -> tuple[Trajectory, list[float]] | None:
    """The motions of ``run`` joined and timed as one, and the times of its ends and junctions [s].

    Slowed where a line's tool would exceed its speed limit; ``None`` where they cannot be joined.
    """
    limits = robot.limits
    try:
        marked = joined_motion(
            [Piece(m.path, m.rigid) for m in run],
            (limits.velocity, limits.acceleration, limits.jerk),
            torque=run[0].required.dynamics,
        )
    except (PlanningError, NoSolutionError):
        return None
    trajectory, times = marked.trajectory, [0.0, *marked.times.tolist(), marked.trajectory.duration]
    parts_s = list(itertools.pairwise(times))
    slower = max(
        _tool_speed_excess(robot, m.line, trajectory.between(*span))
        for m, span in zip(run, parts_s, strict=True)
    )
    if slower > 1.0:
        trajectory, times = trajectory.time_scaled(slower), [t * slower for t in times]
    return trajectory, times


def _verified_parts(
    robot: ck.Robot, run: list[PlannedMotion], trajectory: Trajectory, times: list[float]
) -> list[TimedMotion] | None:
    """``trajectory`` cut at ``times``, each part verified as its motion's segment (``None``: one fails)."""
    parts = []
    for k, motion in enumerate(run):
        part = trajectory.between(times[k], times[k + 1])
        line, held = motion.line, motion.held
        if line is not None:  # the geometric promises first: cheaper than the certified checks
            deviation = line_deviation(robot, line.frame, line.geometry, part, line.line.tolerance)
            if not deviation.within(line.line.tolerance):
                return None
        if held is not None:
            constraint = held.constraint
            angle = orientation_deviation(robot, held.frame, constraint, constraint.reference(), part)
            if angle.angle_rad > constraint.angle_rad:
                return None
            held = dataclasses.replace(held, trajectory=part, deviation=angle)
        verification = verify_finer_where_needed(motion.problem, part, motion.required)
        if not verification.accepted:
            return None
        if line is not None:
            line = dataclasses.replace(line, trajectory=part, deviation=deviation, verification=verification)
        parts.append(TimedMotion(part, verification, line, held))
    return parts


def _tool_speed_excess(robot: ck.Robot, line: LineMotion | None, part: Trajectory) -> float:
    """How many times a line's tool speed limit its part exceeds (1: none, or within it)."""
    if line is None or line.line.tool_speed_m_s is None:
        return 1.0
    deviation = line_deviation(robot, line.frame, line.geometry, part, line.line.tolerance)
    return max(1.0, deviation.tool_speed_m_s / line.line.tool_speed_m_s)
