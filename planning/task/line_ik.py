"""The joint path that holds a tool frame on a straight line: inverse kinematics by continuation.

From the start configuration the line is walked in small steps (:data:`STEP_M`,
:data:`STEP_RAD`): each step predicts the joints by the Jacobian's damped pseudo-inverse of
the line's constant twist, then Newton's method with damped least squares puts the frame on
the line's pose there, to :data:`IK_SHARE` of the tolerance, within the joint ranges (compiled:
:func:`~planning.task.line_walk.walk_line`). The
samples are joined by a quintic spline in the progress ``sigma`` (C4: the jerk of the timed
motion is continuous) and the spline's midpoints are checked against the line by forward
kinematics; where the spline strays, the steps are halved.

Where the walk cannot go on, :class:`~planning.errors.ToolLineBrokenError` names the share of the
line achieved and why: a joint at its limit, a singularity (a joint would have to move
:data:`LARGEST_JOINT_STEP` for one small step of the tool), or a pose the arm cannot take
(out of reach, or an orientation a 5-joint arm cannot hold).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

import cpr_kin as ck
from cpr_kin.kinematics.tool_chain import ToolChain
from planning.curves.interpolating_spline import spline_through
from planning.curves.trajectory import Trajectory
from planning.errors import ToolLineBrokenError
from planning.task.joint_ranges import LIMIT_GAIN, LIMIT_ZONE, RANGE_INSETS, beyond_range, joint_range
from planning.task.line_deviation import rotation_angles
from planning.task.line_walk import walk_line
from planning.task.tool_line import LineGeometry, LineTolerance

FloatArray = NDArray[np.float64]

STEP_M = 0.002
"""Largest move of the tool between two samples of the walk [m]."""
STEP_RAD = 0.02
"""Largest turn of the tool between two samples of the walk [rad]."""
FEWEST_STEPS = 16
"""Fewest steps of a walk."""
MOST_STEPS = 8192
"""Most steps of a walk (a 16 m line at :data:`STEP_M`)."""
IK_SHARE = 1e-3
"""How close each sample is put to the line, as a share of the tolerance."""
REACH_SHARE = 0.5
"""How far a sample may stay from the line's pose where the arm cannot take it exactly (a 5-joint
arm holding an orientation), as a share of the tolerance; the timed motion's certified
deviation must still be within the whole tolerance."""
PROGRESS = 1e-3
"""The relative decrease of a Newton step's error below which it has settled."""
SPLINE_DEGREE = 5
"""Degree of the spline through the samples: C4, so that the timed motion's jerk is continuous."""
SPLINE_SHARE = 0.05
"""How far the spline may stray from the line between samples, as a share of the tolerance."""
NEWTON_STEPS = 40
"""Most Newton steps per sample."""
DAMPING = 1e-5
"""Damping of the least squares, relative to the size of the tolerance-weighted Jacobian."""
LARGEST_JOINT_STEP = 0.25
"""Most a joint may move between two samples [rad or m]: more means a singularity."""
SINGULAR = 1e-4
"""Smallest singular value of the tolerance-weighted Jacobian, relative to its largest."""


@dataclass(frozen=True)
class JointLine:
    """A joint path that keeps the tool frame on its line (:func:`joint_line`).

    Attributes:
        frame: the tool frame.
        geometry: the line.
        sigma: ``(n,)`` the progress of each sample, 0 to 1.
        samples: ``(n, nq)`` the configurations at ``sigma`` [rad, m].
        path: the quintic spline through the samples, in ``sigma`` (knots 0 to 1).
    """

    frame: str
    geometry: LineGeometry
    sigma: FloatArray
    samples: FloatArray
    path: Trajectory


def joint_line(
    robot: ck.Robot, q_start: FloatArray, frame: str, geometry: LineGeometry, tolerance: LineTolerance
) -> JointLine:
    """The joint path from ``q_start`` that holds ``frame`` on ``geometry`` within ``tolerance``.

    Raises:
        ToolLineBrokenError: the walk stops before the end (the share achieved and why).
    """
    steps = _step_count(geometry)
    q = np.asarray(q_start, dtype=float)
    inset, insets = np.zeros(robot.nq), 0
    while True:
        sigma = np.linspace(0.0, 1.0, steps + 1)

        def walk(
            gain: float, scales: FloatArray, sigma: FloatArray = sigma, inset: FloatArray = inset
        ) -> tuple[FloatArray, float]:
            return _walk(robot, q, frame, geometry, tolerance, sigma, gain, inset, scales)

        samples, residual = _walked(robot, walk)
        path = spline_through(sigma, samples, SPLINE_DEGREE)
        beyond = beyond_range(robot, path)
        if beyond.any() and insets < RANGE_INSETS:  # samples at a limit, the spline past it
            inset, insets = inset + 2.0 * beyond, insets + 1
            continue
        middles = 0.5 * (sigma[1:] + sigma[:-1])
        excess = _excess(robot, frame, geometry, tolerance, middles, path(middles))
        if excess <= residual + SPLINE_SHARE or 2 * steps > MOST_STEPS:
            return JointLine(frame, geometry, sigma, samples, path)
        steps *= 2


def _walked(
    robot: ck.Robot, walk: Callable[[float, FloatArray], tuple[FloatArray, float]]
) -> tuple[FloatArray, float]:
    """The first of the walks ``walk(gain, scales)`` that reaches the line's end.

    First with the steps least in time (the robot's speed scales), then, on a redundant arm, with
    its null space pulling joints from their limits (``LIMIT_GAIN``,
    :mod:`planning.task.joint_ranges`): the pull lengthens the joints' motion on lines that need
    none, so only on a break. Where the joints' speeds differ, both again with the plain steps
    (scales of 1): a walk that prefers the fast joints may drive one into its limit where the
    plain steps share the motion otherwise (Romeo's elbow, at its limit at a line's start). Of
    the breaks, the one furthest along is raised.
    """
    speeds = np.array(robot.limits.speed_scales)
    gains = (0.0, LIMIT_GAIN) if robot.nq > 6 else (0.0,)
    metrics = (speeds, np.ones(robot.nq)) if robot.limits.speeds_differ else (speeds,)
    breaks = []
    for scales in metrics:
        for gain in gains:
            try:
                return walk(gain, scales)
            except ToolLineBrokenError as broken:
                breaks.append(broken)
    raise max(breaks, key=lambda broken: broken.fraction) from None


def _step_count(geometry: LineGeometry) -> int:
    moves = max(
        float(np.linalg.norm(geometry.shift_m)) / STEP_M, float(np.linalg.norm(geometry.turn)) / STEP_RAD
    )
    return int(np.clip(math.ceil(moves), FEWEST_STEPS, MOST_STEPS))


def _weights(tolerance: LineTolerance) -> FloatArray:
    return np.array([1.0 / tolerance.position_m] * 3 + [1.0 / tolerance.angle_rad] * 3)


def _walk(
    robot: ck.Robot,
    q: FloatArray,
    frame: str,
    geometry: LineGeometry,
    tolerance: LineTolerance,
    sigma: FloatArray,
    limit_gain: float = 0.0,
    inset: FloatArray | float = 0.0,
    scales: FloatArray | None = None,
) -> tuple[FloatArray, float]:
    """The samples of the walk at ``sigma`` and their largest error, over the tolerance.

    Compiled (:func:`~planning.task.line_walk.walk_line`). ``limit_gain``: the pull of joints
    from their limits (:data:`~planning.task.joint_ranges.LIMIT_GAIN`), none by default.
    ``scales`` ``(nq,)``: the joints' weights in each step (default: the robot's speed
    scales, the steps least in time; ones: the plain least-squares steps).
    """
    bounds = joint_range(robot, inset)
    weights = _weights(tolerance)
    chain, tool = ToolChain.of(robot, frame).arrays
    rates = np.array([DAMPING, PROGRESS, IK_SHARE, NEWTON_STEPS], dtype=float)
    joint_scales = np.array(robot.limits.speed_scales if scales is None else scales, dtype=float)
    newton = (weights, joint_scales, *bounds, rates)
    twist = np.concatenate([geometry.shift_m, geometry.start.rotation @ geometry.turn]) * weights
    line = (sigma, geometry.start.translation + sigma[:, None] * geometry.shift_m, geometry.rotations(sigma))
    checks = np.array([limit_gain, LIMIT_ZONE, REACH_SHARE, LARGEST_JOINT_STEP], dtype=float)
    walk = (twist, np.stack(joint_range(robot)), checks)
    samples, residual, broken, found, excess = walk_line(
        np.asarray(q, dtype=float), chain, tool, line, newton, walk
    )
    if broken >= 0:
        last = samples[broken - 1]
        jacobian = _jacobian(robot.model, robot.data, robot.frame_id(frame), last) * weights[:, None]
        raise ToolLineBrokenError(
            _why(robot, frame, found, np.abs(found - last), excess, jacobian), float(sigma[broken - 1])
        )
    return samples, residual


def _jacobian(model: object, data: object, fid: int, q: FloatArray) -> FloatArray:
    return np.asarray(pin.computeFrameJacobian(model, data, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED))


def _why(
    robot: ck.Robot, frame: str, q: FloatArray, jump: FloatArray, excess: float, jacobian: FloatArray
) -> str:
    """Why the walk stops at ``q``, in words (``jacobian``: ``frame``'s, weighted, at the last sample)."""
    names, lower, upper = robot.joint_names, *joint_range(robot)
    if jump.max() > LARGEST_JOINT_STEP:
        j = int(np.argmax(jump))
        return (
            f"it passes near a singularity: joint '{names[j]}' would move {jump[j]:.3g} "
            f"{robot.joint_unit(names[j])} for one step of the tool (at most {LARGEST_JOINT_STEP:g})"
        )
    at_limit = np.flatnonzero((q <= lower + 1e-9) | (q >= upper - 1e-9))
    if at_limit.size:
        j = int(at_limit[0])
        return (
            f"joint '{names[j]}' reaches its limit ({q[j]:.4g} {robot.joint_unit(names[j])}, "
            f"range [{lower[j]:g}, {upper[j]:g}])"
        )
    values = np.linalg.svd(jacobian, compute_uv=False)
    if values[-1] < SINGULAR * values[0]:
        moving = [names[j] for j in np.flatnonzero(np.linalg.norm(jacobian, axis=0) > 0.0)]
        rank = int(np.count_nonzero(values >= SINGULAR * values[0]))
        if rank == len(moving) < len(jacobian):  # too few joints, not a singularity of them
            return (
                f"frame '{frame}' is moved by {len(moving)} joint(s) ({', '.join(moving)}), fewer than the "
                f"{len(jacobian)} values of its pose the line holds: hold a frame the whole arm moves, such "
                "as the tool's"
            )
        return "it passes through a singularity of the arm"
    return (
        f"the arm cannot take the line's pose there (it stays {excess:.3g} x the tolerance away: "
        "out of reach, or an orientation its joints cannot hold)"
    )


def _excess(
    robot: ck.Robot,
    frame: str,
    geometry: LineGeometry,
    tolerance: LineTolerance,
    sigma: FloatArray,
    configurations: FloatArray,
) -> float:
    """The largest error of ``configurations`` from the line's poses at ``sigma``, over the tolerance.

    As :func:`~planning.task.line_newton.newton_to_pose` measures it, for all at once: the
    rotation error's norm is the relative rotation's angle.
    """
    poses = ck.frame_poses(robot, configurations, frame)
    on_line = geometry.start.translation + sigma[:, None] * geometry.shift_m
    distance = np.linalg.norm(poses[:, :3, 3] - on_line, axis=1) / tolerance.position_m
    relative = np.einsum("nji,njk->nik", poses[:, :3, :3], geometry.rotations(sigma))
    return float(max(distance.max(), (rotation_angles(relative) / tolerance.angle_rad).max()))
