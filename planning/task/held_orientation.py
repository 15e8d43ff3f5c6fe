"""A free motion that keeps an orientation constraint: the free path bent onto it, or a path planned on it.

The planner's free motion from start to goal ignores the constraint. Its path is sampled (a
joint moves at most :data:`STEP` between samples) and each sample is moved the least onto the
constraint, the tool held where the free path has it
(:class:`~planning.task.orientation_projection.Projector`); start and goal must keep the
constraint and are left as they are. Where that bent path does not keep the margins (the
free path turned the tool to pass an obstacle) or cannot be bent (a pose the arm cannot
hold there, a singularity), a path is planned on the constraint itself
(:func:`~planning.task.orientation_rrt.orientation_path`). A quintic spline joins the samples
(C4), its midpoints checked and, where it strays, projected midpoints inserted; the clearance
of every sample is checked; the path is timed exactly
(:func:`~planning.curves.on_path_timing.time_on_path`), its knots brought closer until the
certified angle (:func:`~planning.task.orientation.orientation_deviation`) keeps the constraint.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.common.arrays import distinct_sorted
from planning.curves.interpolating_spline import chord_parameter, spline_through
from planning.curves.on_path_timing import time_on_path
from planning.curves.trajectory import Trajectory
from planning.errors import NoSolutionError, PlanningError
from planning.pipeline.deadline import Deadline
from planning.pipeline.verification import Requirements, verify_trajectory
from planning.task.line_motion import first_blocked, why_blocked
from planning.task.orientation import OrientationConstraint, OrientationDeviation, orientation_deviation
from planning.task.orientation_projection import Projector
from planning.task.orientation_rrt import orientation_path

FloatArray = NDArray[np.float64]

STEP = 0.01
"""Largest move of a joint between two samples of the free path [rad or m]."""
FEWEST_SAMPLES, MOST_SAMPLES = 16, 8192
"""Fewest and most samples of the path."""
LARGEST_JOINT_STEP = 0.25
"""Most a joint may move between two samples once bent [rad or m]: more means a singularity."""
SPLINE_SHARE = 0.75
"""The spline may reach this share of the allowed angle at its midpoints."""
SPLINE_ROUNDS = 6
"""Most rounds of midpoints inserted where the spline strays."""
NODE_STEP_S, KNOT_HALVINGS = 0.1, 4
"""The timing's knot spacing [s], and how often it may be halved to keep the constraint."""
PROBE_STEP = 0.05
"""Largest move of a joint between two samples of a goal's probe [rad or m] (:func:`goal_on_constraint`)."""
FEWEST_SPARSE = 8
"""Fewest samples a sparser spline goes through (:data:`SPARSER`; a quintic needs six)."""
SPARSER = (16, 4)
"""Every how many samples of a path on the constraint (the free path's, bent, or the steps of one
planned on it) a spline is tried through before one through them all, sparsest first. Each
sample is projected on its own, and a spline through every one follows the zigzags of their
projections, which the timing crawls through (docs/tuning.md, Tool lines). A sparser spline that
leaves the constraint gets projected midpoints; one whose timed motion is not clear of the
obstacles (certified) gives way to the next."""


@dataclass(frozen=True)
class HeldMotion:
    """A free motion that keeps an orientation constraint (:func:`hold_orientation`).

    Attributes:
        constraint: the constraint, its reference resolved (the frame's at the start if none given).
        frame: the constrained frame.
        samples: ``(n, nq)`` the path's samples [rad, m].
        path: the quintic spline through them, the geometric path (parameter 0 to 1).
        trajectory: the timed motion, at rest at both ends.
        deviation: its certified angle from the constraint.
        bent: the free path bent onto the constraint (``False``: a path planned on it).
    """

    constraint: OrientationConstraint
    frame: str
    samples: FloatArray
    path: Trajectory
    trajectory: Trajectory
    deviation: OrientationDeviation
    bent: bool = True


def hold_orientation(
    world: ck.CollisionWorld,
    free: Trajectory,
    constraint: OrientationConstraint,
    required: Requirements,
    seed: int = 0,
    deadline: Deadline | None = None,
) -> HeldMotion:
    """``free``'s path bent onto ``constraint``, or one planned on it, timed within ``required``'s limits.

    The planning on the constraint stops where ``deadline`` has passed (:func:`orientation_path`).

    Raises:
        PlanningError: the start or the goal does not keep the constraint (bad input).
        NoSolutionError: neither the bent path nor one planned on the constraint keeps it and
            the margins (why, for both), or the timed motion leaves it.
    """
    ends = free(free.knots[[0, -1]])
    projector = Projector.from_start(world.robot, constraint, ends[0])
    frame, constraint = projector.frame, projector.constraint
    for label, angle in zip(("start", "goal"), projector.angles(ends), strict=True):
        if angle > constraint.angle_rad:
            raise PlanningError(
                f"the motion's {label} holds '{frame}' {angle:.4g} rad from the constraint's orientation "
                f"about {list(constraint.axes)}; allowed {constraint.angle_rad:.4g} rad: give a {label} that "
                "keeps it (a pose goal with that orientation)"
            )
    try:
        bent = _bent(projector, _raw_samples(free))
        _refuse_blocked(world, bent, required)
        return _held_sparsest(world, projector, bent, required, bent=True)
    except NoSolutionError as why:  # blocked, or it cannot be joined or timed (a corner it made)
        try:
            rng = np.random.default_rng(seed)
            planned = orientation_path(world, projector, ends[0], ends[1], required, rng, deadline)
        except NoSolutionError as failed:
            raise NoSolutionError(f"the free path bent onto the constraint: {why}; {failed}") from None
    return _held_sparsest(world, projector, planned, required, bent=False)


def _held_sparsest(
    world: ck.CollisionWorld, projector: Projector, samples: FloatArray, required: Requirements, bent: bool
) -> HeldMotion:
    """:func:`_held` through every :data:`SPARSER`-th of ``samples`` where that keeps the motion clear.

    Never through fewer than :data:`FEWEST_SPARSE`.
    """
    for every in SPARSER:
        kept = samples[distinct_sorted(np.arange(0, len(samples), every), len(samples) - 1)]
        if len(kept) < FEWEST_SPARSE:
            continue
        with contextlib.suppress(NoSolutionError):
            motion = _held(world, projector, kept, required, bent)
            if verify_trajectory(world, motion.trajectory, required).accepted:
                return motion
    return _held(world, projector, samples, required, bent)


def goal_on_constraint(
    robot: ck.Robot, constraint: OrientationConstraint, q_start: FloatArray
) -> Callable[[FloatArray], bool]:
    """A test of a constrained move's goal: the straight joint path from ``q_start`` bends onto it.

    A pose has several IK solutions, on branches (an elbow up or down, a wrist flipped) that
    no motion keeping the constraint joins, and the nearest the start may lie on another
    branch than the start's: a UR whose base is near its limit reaches its goal's branch by
    turning the other way round, farther than a flip. A goal passes where the straight joint
    path to it, sampled every :data:`PROBE_STEP` and each sample moved the least onto the
    constraint (as a free path is bent), keeps it without a jump: a way along the
    constraint, obstacles aside.
    """
    projector = Projector.from_start(robot, constraint, q_start)

    def reached(q_goal: FloatArray) -> bool:
        count = int(np.clip(math.ceil(np.abs(q_goal - q_start).max() / PROBE_STEP) + 1, 3, MOST_SAMPLES))
        straight = q_start + np.linspace(0.0, 1.0, count)[:, None] * (q_goal - q_start)
        try:
            _bent(projector, straight)
        except NoSolutionError:
            return False
        return True

    return reached


def _held(
    world: ck.CollisionWorld, projector: Projector, samples: FloatArray, required: Requirements, bent: bool
) -> HeldMotion:
    """The samples joined by a spline on it, refused where blocked, timed; ``bent``: how found."""
    samples, path = _joined(projector, samples)
    _refuse_blocked(world, samples, required)
    trajectory, deviation = _timed(projector, path, required)
    return HeldMotion(projector.constraint, projector.frame, samples, path, trajectory, deviation, bent)


def _raw_samples(free: Trajectory) -> FloatArray:
    """``(n, nq)`` samples of the free path, a joint moving at most :data:`STEP` between two."""
    dense = free(np.linspace(free.knots[0], free.knots[-1], 4096))
    travel = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(dense, axis=0)).max(axis=1))])
    count = int(np.clip(math.ceil(travel[-1] / STEP) + 1, FEWEST_SAMPLES, MOST_SAMPLES))
    at = np.interp(np.linspace(0.0, travel[-1], count), travel, np.arange(len(dense)))
    times = np.interp(at, np.arange(len(dense)), np.linspace(free.knots[0], free.knots[-1], len(dense)))
    return np.asarray(free(times))


def _bent(projector: Projector, raw: FloatArray) -> FloatArray:
    """Each inner sample of ``raw`` moved the least onto the constraint, the tool kept on the free path."""
    samples = [raw[0]]
    for k in range(1, len(raw) - 1):
        q, angle = projector.project(raw[k], keep_position=True)
        if angle > projector.aim_rad:
            raise NoSolutionError(
                f"the arm cannot turn '{projector.frame}' back within {projector.aim_rad:.4g} rad about "
                f"{list(projector.constraint.axes)} at {100 * k / (len(raw) - 1):.0f} % of the free path "
                f"({angle:.4g} rad)"
            )
        samples.append(q)
    samples.append(raw[-1])
    bent = np.array(samples)
    jumps = np.abs(np.diff(bent, axis=0)).max(axis=1)
    if jumps.max() > LARGEST_JOINT_STEP:
        k = int(np.argmax(jumps))
        raise NoSolutionError(
            f"bending it passes near a singularity at {100 * k / (len(raw) - 1):.0f} % of the free path "
            f"(a joint would move {jumps[k]:.3g} between two samples)"
        )
    return bent


def _joined(projector: Projector, samples: FloatArray) -> tuple[FloatArray, Trajectory]:
    """The samples, with projected midpoints where the quintic spline through them strays, and the spline."""
    for _ in range(SPLINE_ROUNDS):
        sigma = chord_parameter(samples)
        path = spline_through(sigma, samples)
        middles = 0.5 * (sigma[1:] + sigma[:-1])
        strays = projector.angles(path(middles)) > SPLINE_SHARE * projector.constraint.angle_rad
        if not strays.any():
            return samples, path
        inserted = [projector.project(q, keep_position=True)[0] for q in path(middles[strays])]
        at = np.flatnonzero(strays) + 1
        samples = np.insert(samples, at, np.array(inserted), axis=0)
    raise NoSolutionError("the orientation-held path cannot be joined smoothly (its spline strays)")


def _refuse_blocked(world: ck.CollisionWorld, samples: FloatArray, required: Requirements) -> None:
    """Raise where the first sample does not keep the clearances, with its share of the path."""
    first = first_blocked(world, samples, required)
    if first is not None:
        what = why_blocked(world, samples[first], required)
        raise NoSolutionError(f"{what} at {100 * chord_parameter(samples)[first]:.0f} % of the path")


def _timed(
    projector: Projector, path: Trajectory, required: Requirements
) -> tuple[Trajectory, OrientationDeviation]:
    """The motion on ``path`` and its certified angle, with knots close enough to keep the constraint."""
    robot, constraint = projector.robot, projector.constraint
    limits = robot.limits
    for halving in range(KNOT_HALVINGS + 1):
        trajectory = time_on_path(
            path,
            limits.velocity,
            limits.acceleration,
            limits.jerk,
            node_step_s=NODE_STEP_S / 2**halving,
            torque=required.dynamics,
        )
        deviation = orientation_deviation(robot, projector.frame, constraint, projector.reference, trajectory)
        if deviation.angle_rad <= constraint.angle_rad:
            return trajectory, deviation
    raise NoSolutionError(
        f"the timed motion turns '{projector.frame}' {deviation.angle_rad:.4g} rad from the constraint's "
        f"orientation (certified; allowed {constraint.angle_rad:.4g} rad)"
    )
