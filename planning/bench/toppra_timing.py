"""TOPP-RA timing and verification of a sampling planner's path, shared by the peers.

A clamped cubic spline through the path's vertices is timed by TOPP-RA (``toppra``) under
the joints' velocity and acceleration limits (it has no jerk limit) and verified by the same
certified continuous check as the firefly planner's trajectories. Where the cubic leaves a
joint's range (a path that runs along a joint limit, as the Fetch's torso at its lowest does),
the shape-preserving PCHIP interpolant through the same vertices is timed instead: between
two vertices it stays within their values, so within every range they are in; and TOPP-RA's
trajectory then follows it exactly (its constant-acceleration parametrisation, where the
default fits a spline in time that may stray out of the range again).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.trajectory import interval_speed_bounds
from planning.pipeline.scene import Scene

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class SamplingResult:
    """Outcome of the RRT-Connect pipeline on one scene.

    Attributes:
        success: a path was found, timed and verified.
        reason: why not, when it failed.
        waypoints: ``(K, nq)`` the simplified path's vertices.
        duration: trajectory duration [s].
        min_clearance: certified clearance of the timed trajectory [m].
        path_length: length of the path in joint space, each joint scaled by its range.
        max_abs_jerk: largest |jerk| of any joint, from the timed spline (its acceleration
            jumps at the spline's knots, so this samples its finite pieces).
        jerk_over_limit: the largest |jerk| / jerk limit over the joints, the same way
            (TOPP-RA knows no jerk limit).
        planning_time_s: wall time of search, simplification, timing and verification [s].
        timed: TOPP-RA's trajectory, ``timed(t, order)`` at times ``t`` [s] (``None`` when it
            failed before timing): a benchmark reads its torques from it, untimed.
    """

    success: bool
    reason: str
    waypoints: FloatArray
    duration: float
    min_clearance: float
    path_length: float
    max_abs_jerk: float
    jerk_over_limit: float
    planning_time_s: float
    timed: Any = field(default=None, repr=False, compare=False)

    @classmethod
    def failure(cls, reason: str, nq: int, started: float) -> SamplingResult:
        """A failed run: ``reason``, no path, figures NaN; ``started`` is its ``perf_counter()``."""
        nan = float("nan")
        return cls(False, reason, np.empty((0, nq)), nan, nan, nan, nan, nan, time.perf_counter() - started)


def planning_clearance_m(scene: Scene) -> float:
    """Clearance a sampling planner's states and segments keep [m].

    The margin plus the verification step, as the firefly's fitness requires at its samples:
    the timed spline strays a little from the straight segments between the path's vertices.
    """
    return scene.safety_margin + scene.planner.verify_step_m


def import_toppra() -> None:
    """Import the TOPP-RA modules :func:`time_and_verify` imports on its first call.

    A benchmark calls it before timing the peer warm (the imports take a few tenths of a second).
    """
    import toppra
    import toppra.algorithm
    import toppra.constraint  # noqa: F401


def time_and_verify(
    robot: ck.Robot, world: ck.CollisionWorld, scene: Scene, waypoints: FloatArray, started: float
) -> SamplingResult:
    """Time a path of joint-space ``waypoints`` ``(K, nq)`` with TOPP-RA, then verify it.

    A clamped cubic spline through the waypoints (parametrised by their range-scaled joint
    distance) is timed under the velocity and acceleration limits and verified by the
    certified continuous check against the scene's margin; ``started`` is the
    ``time.perf_counter()`` of the planner's start.
    """
    import toppra
    import toppra.algorithm
    import toppra.constraint

    limits = robot.limits
    steps = np.linalg.norm(np.diff(waypoints / limits.range, axis=0), axis=1)
    keep = np.concatenate([[True], steps > 1e-9])
    waypoints = waypoints[keep]
    s_grid = np.concatenate([[0.0], np.cumsum(steps[steps > 1e-9])])
    if len(waypoints) < 2:
        return SamplingResult.failure("the simplified path is a single point", robot.nq, started)
    geometric = _geometric_path(s_grid / s_grid[-1], waypoints, limits)
    constraints = [
        toppra.constraint.JointVelocityConstraint(np.column_stack([-limits.velocity, limits.velocity])),
        toppra.constraint.JointAccelerationConstraint(
            np.column_stack([-limits.acceleration, limits.acceleration])
        ),
    ]
    exact = "ParametrizeConstAccel" if isinstance(geometric, PchipPath) else None  # on the path, in range
    timed = toppra.algorithm.TOPPRA(
        constraints, geometric, gridpoints=np.linspace(0, 1, 401), parametrizer=exact
    ).compute_trajectory(0, 0)
    if timed is None:
        return SamplingResult.failure("TOPP-RA found no timing", robot.nq, started)
    duration = float(timed.duration)
    dense = np.linspace(0.0, duration, 4001)
    positions = np.asarray(timed(dense))
    speeds = np.abs(np.asarray(timed(dense, 1))).max(axis=0) * 1.05 + 1e-9  # sampled, with 5 % slack
    accelerations = np.abs(np.asarray(timed(dense, 2))).max(axis=0) * 1.05 + 1e-9
    radii = ck.motion_radii(robot)

    def joint_speeds(times: FloatArray) -> FloatArray:  # as ours: each interval's own speed bound
        return interval_speed_bounds(times, np.asarray(timed(times, 1)), speeds, accelerations)

    def interval_speed(times: FloatArray) -> FloatArray:
        return joint_speeds(times) @ radii

    check = ck.check_curve(
        world,
        lambda t: np.asarray(timed(np.asarray(t))),
        0.0,
        duration,
        speeds,
        scene.safety_margin,
        scene.planner.verify_step_m,
        interval_speed,
    )
    if check.accepted and world.self_collision:  # the robot's own pairs, certified as ours are
        from cpr_kin.certified.self_curve import check_self_curve

        self_check = check_self_curve(
            world.self_collision,
            lambda t: np.asarray(timed(np.asarray(t))),
            (0.0, duration),
            speeds,
            scene.self_margin,
            scene.planner.self_step_m,
            joint_speeds,
        )
        if not self_check.accepted:
            check = dataclasses.replace(check, accepted=False, certified_min_m=self_check.certified_min_m)
    jerk = sampled_jerk(dense, np.asarray(timed(dense, 2)))
    length = float(np.linalg.norm(np.diff(positions / limits.range, axis=0), axis=1).sum())
    inside = bool(np.all(positions >= limits.lower - 1e-9) and np.all(positions <= limits.upper + 1e-9))
    reason = (
        ""
        if check.accepted and inside
        else (
            f"certified clearance {check.certified_min_m:.4f} m below the margin"
            if not check.accepted
            else "leaves a joint range"
        )
    )
    return SamplingResult(
        success=check.accepted and inside,
        reason=reason,
        waypoints=waypoints,
        duration=duration,
        min_clearance=check.certified_min_m,
        path_length=length,
        max_abs_jerk=float(np.abs(jerk).max()),
        jerk_over_limit=float(np.max(np.abs(jerk) / limits.jerk)),
        planning_time_s=time.perf_counter() - started,
        timed=timed,
    )


def sampled_jerk(times: FloatArray, accelerations: FloatArray) -> FloatArray:
    """``(K - 1, nq)`` the jerk between samples ``times`` ``(K,)`` [s] of ``accelerations`` ``(K, nq)``.

    Finite differences: a TOPP-RA trajectory's acceleration jumps at its knots, and this
    measures its finite pieces (the peers' "jerk over the limit").
    """
    return np.asarray(np.diff(accelerations, axis=0) / np.diff(times)[:, None])


class PchipPath:
    """The shape-preserving PCHIP interpolant of ``waypoints`` at ``s``, as a TOPP-RA geometric path.

    Between two waypoints each joint stays within their two values (scipy's ``PchipInterpolator``).
    """

    def __init__(self, s: FloatArray, waypoints: FloatArray) -> None:
        from scipy.interpolate import PchipInterpolator

        spline = PchipInterpolator(s, waypoints)
        self.s, self.q = s, waypoints
        self.derivatives = (spline, spline.derivative(), spline.derivative(2))

    def __call__(self, positions: FloatArray, order: int = 0) -> FloatArray:
        """The path's ``order``-th derivative (0 to 2) at ``positions``."""
        return np.asarray(self.derivatives[order](positions))

    @property
    def dof(self) -> int:
        """Number of joints."""
        return int(self.q.shape[1])

    @property
    def path_interval(self) -> FloatArray:
        """First and last path positions."""
        return np.array([self.s[0], self.s[-1]])

    @property
    def waypoints(self) -> tuple[FloatArray, FloatArray]:
        """The path positions and the waypoints."""
        return self.s, self.q


def _geometric_path(s: FloatArray, waypoints: FloatArray, limits: ck.JointLimits) -> object:
    """The path through ``waypoints`` at ``s`` in [0, 1]: the clamped cubic, else PCHIP (module doc)."""
    import toppra

    cubic = toppra.SplineInterpolator(s, waypoints, bc_type="clamped")
    q = cubic(np.linspace(0.0, 1.0, 2001))
    if np.all(q >= limits.lower - 1e-9) and np.all(q <= limits.upper + 1e-9):
        return cubic
    return PchipPath(s, waypoints)
