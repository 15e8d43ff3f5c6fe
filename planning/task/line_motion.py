"""A straight tool line planned: joint path, timing on it, and every promise verified.

:func:`plan_line` reads in four steps: the line's geometry from the start pose, the joint
path that holds the tool on it (:func:`~planning.task.line_ik.joint_line`), the clearance of
that path's samples (where the first falls short the line is blocked), then the timing on the
path (:func:`~planning.curves.on_path_timing.time_on_path`) with its certified deviation and
the verification every trajectory of the planner passes (clearance certified, C3, ranges,
limits, torques). The motion is at rest at both ends, as a grasp's approach and retreat are.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

import cpr_kin as ck
from planning.curves.on_path_timing import time_on_path
from planning.curves.path_timing import NODE_STEP_S
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError, ToolLineBrokenError
from planning.pipeline.verification import Requirements, Verification, verify_trajectory
from planning.task.line_deviation import LineDeviation, line_deviation
from planning.task.line_ik import JointLine, joint_line
from planning.task.tool_line import LineGeometry, ToolLine, ToolPose

FloatArray = NDArray[np.float64]

KNOT_HALVINGS = 4
"""How often the trajectory's knot spacing is halved (0.1 s to 6 ms) to keep the septic on the line."""


@dataclass(frozen=True)
class LineMotion:
    """A planned tool line (:func:`plan_line`).

    Attributes:
        line: what was asked.
        frame: the tool frame.
        geometry: the line, from the start pose to the goal pose.
        path: the joint path that holds the tool on it.
        trajectory: the timed motion, at rest at both ends.
        deviation: its certified deviation from the line.
        verification: the planner's verification of the trajectory (clearance, limits, torques).
    """

    line: ToolLine
    frame: str
    geometry: LineGeometry
    path: JointLine
    trajectory: Trajectory
    deviation: LineDeviation
    verification: Verification

    @property
    def start(self) -> ToolPose:
        """The tool's pose at the start, in the base frame."""
        return ToolPose.of(self.geometry.start)

    @property
    def goal(self) -> ToolPose:
        """The tool's pose at the end, in the base frame."""
        return ToolPose.of(self.geometry.goal)


def plan_line(
    world: ck.CollisionWorld, q_start: ArrayLike, line: ToolLine, required: Requirements
) -> LineMotion:
    """The motion from ``q_start`` along ``line``, verified against ``world`` and ``required``.

    Raises:
        CprKinError: ``q_start`` is not a configuration of the robot, or the frame is unknown.
        PlanningError: the line neither moves nor turns, or its start does not keep the clearances.
        ToolLineBrokenError: the line cannot be followed to its end (the share achieved and
            why: a joint limit, a singularity, a pose out of reach, an obstacle, a limit).
    """
    robot = world.robot
    q = robot.configuration(q_start)
    _refuse_blocked(world, q[None], np.zeros(1), required)  # the start first: bad input
    path = line_path(robot, q, line)
    frame, geometry = path.frame, path.geometry
    _refuse_blocked(world, path.samples, path.sigma, required)
    trajectory, deviation = _timed(robot, frame, path, line, required)
    verification = verify_trajectory(world, trajectory, required)
    if not verification.accepted:
        check = verification.check  # where the clearance fails, else from the start (a limit, a torque)
        failed = not check.accepted and np.isfinite(check.worst_time)
        when = float(check.worst_time) if failed else float(trajectory.knots[0])
        raise ToolLineBrokenError(
            "; ".join(verification.problems), _progress_at(robot, frame, path, trajectory, when)
        )
    return LineMotion(line, frame, geometry, path, trajectory, deviation, verification)


def line_path(robot: ck.Robot, q: FloatArray, line: ToolLine) -> JointLine:
    """The joint path from ``q`` that holds ``line``'s frame on it, obstacles aside.

    Raises:
        ToolLineBrokenError: the line cannot be followed to its end (a joint limit, a
            singularity, a pose out of reach).
    """
    frame = robot.tcp_frame if line.frame is None else line.frame
    pose = ck.frame_poses(robot, q, frame)
    start = pin.SE3(pose[:3, :3], pose[:3, 3])
    return joint_line(robot, q, frame, LineGeometry(start, line.goal(start)), line.tolerance)


def _refuse_blocked(
    world: ck.CollisionWorld, samples: FloatArray, sigma: FloatArray, required: Requirements
) -> None:
    """Raise where the first of ``samples`` (at progress ``sigma``) does not keep the clearances.

    A start that does not keep them is bad input, as a scene's start is (a
    :class:`~planning.errors.PlanningError`); a later sample breaks the line there.
    """
    first = first_blocked(world, samples, required)
    if first is None:
        return
    what = why_blocked(world, samples[first], required)
    if first == 0:
        raise PlanningError(f"the line's start configuration does not keep the clearances: {what}")
    raise ToolLineBrokenError(what, float(sigma[first - 1]))


def first_blocked(world: ck.CollisionWorld, samples: FloatArray, required: Requirements) -> int | None:
    """The index of the first of ``samples`` that does not keep the clearances, ``None``: all do."""
    kept = world.keeps_clearance(samples, required.margin_m, required.self_margin_m, ordered=True)
    return None if kept.all() else int(np.argmin(kept))


def why_blocked(world: ck.CollisionWorld, q: FloatArray, required: Requirements) -> str:
    """Why ``q`` does not keep the clearances: the closest obstacle, else the robot itself."""
    closest = world.clearance(q).closest
    if closest is None or closest.distance_m >= required.margin_m:
        return f"the robot comes closer to itself than its self margin {required.self_margin_m} m"
    return (
        f"'{closest.robot_geometry}' is {closest.distance_m:.4f} m from '{closest.obstacle}' "
        f"(margin {required.margin_m} m)"
    )


def _timed(
    robot: ck.Robot, frame: str, path: JointLine, line: ToolLine, required: Requirements
) -> tuple[Trajectory, LineDeviation]:
    """The motion on the path and its deviation, with knots close enough to keep it on the line."""
    limits = robot.limits
    for halving in range(KNOT_HALVINGS + 1):
        trajectory = time_on_path(
            path.path,
            limits.velocity,
            limits.acceleration,
            limits.jerk,
            node_step_s=NODE_STEP_S / 2**halving,
            torque=required.dynamics,
        )
        deviation = line_deviation(robot, frame, path.geometry, trajectory, line.tolerance)
        if line.tool_speed_m_s is not None and deviation.tool_speed_m_s > line.tool_speed_m_s:
            trajectory = trajectory.time_scaled(deviation.tool_speed_m_s / line.tool_speed_m_s)
            deviation = line_deviation(robot, frame, path.geometry, trajectory, line.tolerance)
        if deviation.within(line.tolerance) or halving == KNOT_HALVINGS:
            break
    if deviation.within(line.tolerance):
        return trajectory, deviation
    raise ToolLineBrokenError(
        f"its timed motion leaves the line by {deviation.position_m:.3g} m and {deviation.angle_rad:.3g} rad "
        f"(certified; tolerance {line.tolerance.position_m:g} m, {line.tolerance.angle_rad:g} rad)",
        _progress_at(robot, frame, path, trajectory, deviation.worst_time_s),
    )


def _progress_at(
    robot: ck.Robot, frame: str, path: JointLine, trajectory: Trajectory, time_s: float
) -> float:
    """The line's progress at ``time_s`` of ``trajectory``: the share achieved before it fails."""
    pose = ck.frame_poses(robot, trajectory(np.array([time_s])), frame)
    return float(path.geometry.progress(pose[:, :3, 3], pose[:, :3, :3])[0])
