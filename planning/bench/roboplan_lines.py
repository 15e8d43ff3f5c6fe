"""roboplan's Cartesian path planner (C++, OInK differential IK and TOPP-RA): the peer of a tool line.

:class:`RoboplanLines` gives roboplan the robot as :class:`~planning.bench.roboplan_rrt.RoboplanPeer`
does (our collision model and limits) and plans a straight line of the tool frame from a
configuration with :class:`roboplan.cartesian_planning.CartesianPathPlanner`, time-optimal
under the joints' velocity and acceleration limits (roboplan has no jerk limit there), the
deviation it may allow set to the same tolerance as ours. Needs the ``bench`` extra.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.bench.roboplan_rrt import GROUP, RoboplanPeer
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.task.tool_line import LineTolerance

FloatArray = NDArray[np.float64]
SAMPLE_S = 1e-3
"""roboplan's output sample period [s]."""


@dataclass(frozen=True)
class PeerLine:
    """One roboplan line.

    Attributes:
        success: a trajectory was returned that reaches the goal.
        reason: why not, when it failed.
        planning_time_s: the planner's call [s].
        times: ``(K,)`` sample times [s].
        positions: ``(K, nq)`` the planned joints at them [rad, m].
    """

    success: bool
    reason: str
    planning_time_s: float
    times: FloatArray
    positions: FloatArray


class RoboplanLines:
    """A robot in roboplan for Cartesian lines; plan one with :meth:`plan`."""

    def __init__(self, spec: ck.RobotSpec, robot: ck.Robot, q: FloatArray, tolerance: LineTolerance) -> None:
        from roboplan.cartesian_planning import (
            CartesianPathPlanner,
            CartesianPlannerOptions,
            CartesianSpeedMode,
        )

        moved = np.clip(q + 0.1, robot.limits.lower, robot.limits.upper)  # the peer needs some goal
        scene = Scene(robot=spec, start=Target(q=tuple(q)), goal=Target(q=tuple(moved)), obstacles=())
        self.robot = robot
        self.peer = RoboplanPeer(scene, robot)
        options = CartesianPlannerOptions(
            group_name=GROUP,
            dt=SAMPLE_S,
            speed_mode=CartesianSpeedMode.TimeOptimal,
            max_position_error=tolerance.position_m,
            max_orientation_error=tolerance.angle_rad,
        )
        self.planner = CartesianPathPlanner(self.peer.scene, options)

    def plan(self, q: FloatArray, start: FloatArray, goal: FloatArray, frame: str) -> PeerLine:
        """The line from the tool pose ``start`` to ``goal`` (``(4, 4)`` each) from ``q``, timed."""
        from roboplan.core import CartesianPath, JointConfiguration

        scene, names = self.peer.scene, list(self.robot.joint_names)
        full = np.array(scene.getCurrentJointPositions())
        indices = scene.getJointPositionIndices(names)
        full[indices] = q
        root = self.robot.model.frames[1].name
        path = CartesianPath([root], [frame], [[np.asfortranarray(start), np.asfortranarray(goal)]])
        started = time.perf_counter()
        try:
            timed = self.planner.plan(path, JointConfiguration(list(scene.getJointNames()), full))
        except RuntimeError as exc:
            return PeerLine(
                False, str(exc), time.perf_counter() - started, np.empty(0), np.empty((0, len(q)))
            )
        elapsed = time.perf_counter() - started
        positions = np.array(timed.positions, dtype=float)
        if positions.ndim != 2 or not len(positions):
            return PeerLine(False, "no trajectory", elapsed, np.empty(0), np.empty((0, len(q))))
        order = [list(timed.joint_names).index(name) for name in names]
        return PeerLine(True, "", elapsed, np.array(timed.times, dtype=float), positions[:, order])
