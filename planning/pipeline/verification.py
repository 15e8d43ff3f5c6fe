"""Verification of a timed trajectory against a scene.

What the planner accepts is what ``cpr-plan check`` re-checks: one function serves both.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.collision.decisive import Stop
from planning.curves.continuity import discontinuity
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.pipeline.scene import DEFAULT_SELF_MARGIN_M
from planning.pipeline.target import Target
from planning.pipeline.torques import TorqueProfile, torque_problems, torque_profile

if TYPE_CHECKING:
    from planning.pipeline.problem import Problem

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Verification:
    """Outcome of :func:`verify_trajectory`.

    Attributes:
        check: the certified continuous clearance check.
        problems: one sentence per failed condition (empty when accepted).
        torques: the joint torques at the check instants, if they were checked.
    """

    check: ck.CurveCheck
    problems: tuple[str, ...]
    torques: TorqueProfile | None = None

    @property
    def accepted(self) -> bool:
        """Every condition holds."""
        return not self.problems

    def to_record(self) -> dict[str, Any]:
        """The verdict as plain JSON types (``cpr-plan check --json`` prints it)."""
        return {
            "status": "ok" if self.accepted else "failed",
            "certified_min_clearance_m": self.check.certified_min_m,
            "safety_margin_m": self.check.margin_m,
            "checks": len(self.check.times),
            "certified_step_m": self.check.step_m,
            "problems": list(self.problems),
        }


STOPPED = "was not certified: its check was stopped by the time limit before its verdict"
"""The problem a verification stopped by its caller reports (:func:`verify_trajectory`)."""
LIMIT_TOLERANCE = 1e-9
"""Relative excess of a joint's range or limit that still passes (rounding)."""


def unchecked(margin_m: float, step_m: float) -> ck.CurveCheck:
    """The record of a continuous check that could not be run: nothing certified."""
    return ck.CurveCheck(
        accepted=False,
        margin_m=margin_m,
        step_m=step_m,
        times=np.empty(0),
        clearance_m=np.empty((0, len(ck.GROUPS))),
        certified_min_m=-np.inf,
        sampled_min_m=np.nan,
        worst_time=np.nan,
        worst_group="",
        worst_pair=None,
        violating_groups=ck.GROUPS,
    )


def _interval_speed(trajectory: Trajectory, radii: FloatArray) -> ck.IntervalSpeed:
    """Bounds on the robot's point speed between sample times, from the trajectory's own speeds."""
    return lambda times: trajectory.speed_bounds(times) @ radii


def _self_problems(
    world: ck.CollisionWorld, trajectory: Trajectory, margin_m: float, step_m: float, stop: Stop | None
) -> list[str]:
    """The certified self-collision check's verdict, as problems (none for a robot without pairs).

    Raises:
        CheckStoppedError: ``stop`` said so before the verdict.
    """
    if not world.self_collision:
        return []
    from cpr_kin.certified.self_curve import check_self_curve  # a robot with pairs of its own only

    interval = (float(trajectory.knots[0]), float(trajectory.knots[-1]))
    try:
        check = check_self_curve(
            world.self_collision,
            trajectory.position,
            interval,
            trajectory.extrema(1).peak,
            margin_m,
            step_m,
            trajectory.speed_bounds,
            stop=stop,
        )
    except ck.CheckStoppedError:
        raise
    except ck.CprKinError as exc:
        return [f"cannot be certified clear of itself: {exc}"]
    if check.accepted:
        return []
    pair = "" if check.worst_pair is None else f", {check.worst_pair[0]} to {check.worst_pair[1]}"
    return [
        f"comes within {check.certified_min_m:.4f} m (certified) of itself{pair} "
        f"at t = {check.worst_time:.2f} s (self margin {margin_m} m)"
    ]


@dataclass(frozen=True)
class Requirements:
    """What :func:`verify_trajectory` holds a trajectory to.

    Attributes:
        margin_m: clearance from every obstacle [m].
        step_m: largest robot motion between two checks of the certified check [m].
        self_margin_m: clearance between the robot's checked link pairs [m].
        self_step_m: largest motion of a pair's link against the other between two checks of
            the certified self check [m]; ``None``: ``step_m``.
        endpoints: ``(start, goal)`` it must start and end at; ``None``: not checked.
        dynamics: the robot's torques (payload included) and effort limits; ``None``: not checked.
    """

    margin_m: float
    step_m: float
    self_margin_m: float = DEFAULT_SELF_MARGIN_M
    self_step_m: float | None = None
    endpoints: tuple[Target, Target] | None = None
    dynamics: ck.Dynamics | None = None

    @property
    def self_check_step_m(self) -> float:
        """The certified self check's step [m]: ``self_step_m``, or ``step_m`` where that is ``None``."""
        return self.step_m if self.self_step_m is None else self.self_step_m

    @classmethod
    def of(cls, problem: Problem, endpoints: bool = False) -> Requirements:
        """The scene's requirements (its start and goal too if ``endpoints``), torques included."""
        scene = problem.scene
        return cls(
            margin_m=scene.safety_margin,
            step_m=scene.planner.verify_step_m,
            self_margin_m=scene.self_margin,
            self_step_m=scene.planner.self_step_m,
            endpoints=(scene.start, scene.goal) if endpoints else None,
            dynamics=problem.dynamics,
        )


def verify_trajectory(
    world: ck.CollisionWorld, trajectory: Trajectory, required: Requirements, *, stop: Stop | None = None
) -> Verification:
    """Check a timed trajectory for everything a robot needs of it (``required``'s values).

    - position, velocity, acceleration and jerk are continuous at every knot (C3);
    - the certified clearance (:func:`cpr_kin.check_curve`, robot motion between checks at
      most ``step_m``) is at least ``margin_m`` [m];
    - the certified self-clearance of the robot's checked pairs
      (:func:`cpr_kin.certified.self_curve.check_self_curve`, a pair's motion between checks at most
      ``self_step_m``) is at least ``self_margin_m`` [m];
    - every joint stays within its range, and within its velocity, acceleration and jerk
      limits (exact extrema);
    - with ``endpoints = (start, goal)``: it starts and ends there (:meth:`Target.miss`: a
      joint vector within 1e-6, a ``tcp`` or ``pose`` by forward kinematics within its
      tolerance);
    - with ``dynamics``: every joint torque (RNEA, :func:`~planning.pipeline.torques.torque_profile`)
      within its effort limit every millisecond and at every knot.

    ``stop`` is asked between the certified checks' pieces of work: where it says so, the
    verification ends there, not accepted, saying that its check was stopped (:data:`STOPPED`).
    """
    try:
        return _verified(world, trajectory, required, stop)
    except ck.CheckStoppedError:
        return Verification(check=unchecked(required.margin_m, required.step_m), problems=(STOPPED,))


def _verified(
    world: ck.CollisionWorld, trajectory: Trajectory, required: Requirements, stop: Stop | None
) -> Verification:
    """:func:`verify_trajectory`'s verdict; :class:`~cpr_kin.CheckStoppedError` where ``stop`` says so."""
    margin_m, step_m, endpoints = required.margin_m, required.step_m, required.endpoints
    robot = world.robot
    limits = robot.limits
    tolerance = LIMIT_TOLERANCE
    start, end = trajectory.knots[0], trajectory.knots[-1]
    problems = []
    radii = ck.motion_radii(robot)
    try:
        speeds, local = trajectory.extrema(1).peak, _interval_speed(trajectory, radii)
        check = ck.check_curve(
            world, trajectory.position, start, end, speeds, margin_m, step_m, local, stop=stop
        )
    except ck.CheckStoppedError:
        raise
    except ck.CprKinError as exc:  # too fast to certify: a verdict, not a crash
        problems.append(f"cannot be certified clear of obstacles: {exc}")
        check = unchecked(margin_m, step_m)
    jumps = discontinuity(trajectory, robot.joint_names, robot.joint_units)
    if jumps is not None:
        problems.append(jumps)
    if endpoints is not None:
        for label, target, t in (("start", endpoints[0], start), ("goal", endpoints[1], end)):
            miss = target.miss(robot, trajectory(t))
            if miss is not None:
                problems.append(f"its {label} is {miss} of the scene's {label}")
    if not check.accepted and check.times.size:
        problems.append(
            f"comes within {check.certified_min_m:.4f} m (certified) of an obstacle, margin {margin_m} m: "
            f"closest at t = {check.worst_time:.2f} s between {check.worst_pair} ({check.worst_group})"
        )
    problems += _self_problems(world, trajectory, required.self_margin_m, required.self_check_step_m, stop)
    positions = trajectory.extrema(0)
    for i, name in enumerate(robot.joint_names):
        low, high = positions.minimum[i], positions.maximum[i]
        if low < limits.lower[i] - tolerance or high > limits.upper[i] + tolerance:
            unit = robot.joint_unit(name)
            problems.append(
                f"moves joint '{name}' over [{low:.4g}, {high:.4g}] {unit}, outside its range "
                f"[{limits.lower[i]:g}, {limits.upper[i]:g}] {unit}"
            )
    for r, (kind, limit) in enumerate(
        (("velocity", limits.velocity), ("acceleration", limits.acceleration), ("jerk", limits.jerk)), start=1
    ):
        ratio = trajectory.extrema(r).peak / limit
        if ratio.max() > 1 + tolerance:
            j = int(np.argmax(ratio))
            problems.append(
                f"drives the {kind} of joint '{robot.joint_names[j]}' to {ratio[j]:.3f} x its limit"
            )
    torques = None
    if required.dynamics is not None and required.dynamics.limited:
        torques = torque_profile(required.dynamics, trajectory)
        problems += torque_problems(required.dynamics, torques)
    return Verification(check=check, problems=tuple(problems), torques=torques)


def verify_for_scene(
    problem: Problem,
    trajectory: Trajectory,
    joint_names: Sequence[str] | None = None,
    certified_step_m: float | None = None,
) -> Verification:
    """What ``cpr-plan check`` says of ``trajectory`` against ``problem``'s scene (built anew), its ends too.

    :func:`verify_finer_where_needed` at the scene's steps, then at each finer step a plan may
    have been certified at (:func:`~planning.pipeline.hulls_first.check_steps_m`): the step
    ``certified_step_m`` [m] its file records first, then those of the meshes or their hulls.
    ``joint_names``: the joint order the file records (``trajectory`` is in the robot's).

    Raises:
        PlanningError: ``joint_names`` are not the robot's.
    """
    robot_names = list(problem.robot.joint_names)
    if joint_names is not None and list(joint_names) != robot_names:
        raise PlanningError(f"trajectory joints {list(joint_names)} are not the robot's {robot_names}")

    from planning.pipeline.hulls_first import check_steps_m  # a plan's steps, on the hulls too

    required = Requirements.of(problem, endpoints=True)
    return verify_finer_where_needed(problem, trajectory, required, check_steps_m(problem, certified_step_m))


def verify_finer_where_needed(
    problem: Problem, trajectory: Trajectory, required: Requirements, finer_m: Iterable[float] | None = None
) -> Verification:
    """:func:`verify_trajectory` at ``required``'s steps, then where they cannot certify it at finer ones.

    ``finer_m``: the finer steps [m] in the order to try (``None``: the planner's fallback,
    :func:`~planning.pipeline.problem.finer_step_m`). A finer step only tightens the certified
    bound (more checks, less slack between them); the margins are ``required``'s.
    """
    from planning.pipeline.problem import finer_step_m

    verification = verify_trajectory(problem.world, trajectory, required)
    steps = iter((finer_step_m(problem),) if finer_m is None else finer_m)  # asked for only while refused
    while not verification.accepted and (step_m := next(steps, None)) is not None:
        if step_m < required.step_m:
            self_step_m = min(required.self_check_step_m, step_m)
            finer = dataclasses.replace(required, step_m=step_m, self_step_m=self_step_m)
            verification = verify_trajectory(problem.world, trajectory, finer)
    return verification
