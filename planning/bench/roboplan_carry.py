"""roboplan's constrained RRT-Connect and TOPP-RA: the peer of an upright carry.

roboplan's RRT takes constraints (``roboplan.rrt.PoseConstraint``: a box of the tool frame's
``[x, y, z, roll, pitch, yaw]`` displacement from a region frame) and projects its samples
onto them. The carry's constraint is given as roll and pitch within ``angle / sqrt(2)`` of the
reference each (so that the tilt of the tool's z axis, about ``sqrt(roll^2 + pitch^2)``, stays
within ``angle``), position and yaw free. Its path is timed by TOPP-RA (Hermite, at rest at
each waypoint, on the path) and not shortcut: roboplan's shortcutter knows no constraint. The
scene is our collision model (:class:`~planning.bench.roboplan_rrt.RoboplanPeer`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.bench.roboplan_rrt import GROUP, MAX_NODES, RoboplanPeer
from planning.pipeline.scene import Scene

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class PeerCarry:
    """One constrained roboplan run.

    Attributes:
        success: a path was found and timed.
        reason: why not, when it failed.
        planning_time_s: the constrained RRT-Connect and TOPP-RA [s].
        times: ``(K,)`` TOPP-RA's sample times [s].
        positions: ``(K, nq)`` its positions there.
    """

    success: bool
    reason: str
    planning_time_s: float
    times: FloatArray
    positions: FloatArray


class RoboplanCarry:
    """A scene in roboplan (our collision model), planned under an upright constraint by :meth:`plan`."""

    def __init__(self, scene: Scene, robot: ck.Robot | None = None) -> None:
        self.peer = RoboplanPeer(scene, robot)

    def plan(
        self,
        q_start: FloatArray,
        q_goal: FloatArray,
        reference: FloatArray,
        angle_rad: float,
        time_limit_s: float,
        seed: int = 0,
    ) -> PeerCarry:
        """From ``q_start`` to ``q_goal``, the tool's roll and pitch within ``angle_rad / sqrt(2)`` each."""
        from roboplan.core import JointConfiguration
        from roboplan.rrt import RRT, PoseConstraint, RRTOptions
        from roboplan.toppra import PathParameterizerTOPPRA, SplineFittingMode, TOPPRAOptions

        scene, robot = self.peer.scene, self.peer.problem.robot
        names = list(robot.joint_names)
        region = np.eye(4)
        region[:3, :3] = reference
        each = angle_rad / math.sqrt(2.0)
        lower = np.array([-np.inf, -np.inf, -np.inf, -each, -each, -np.inf])
        constraint = PoseConstraint(scene, GROUP, robot.tcp_frame, lower, -lower, region)
        started = time.perf_counter()
        options = RRTOptions(
            group_name=GROUP, max_nodes=MAX_NODES, max_planning_time=time_limit_s, rrt_connect=True
        )
        planner = RRT(scene, options)
        planner.setRngSeed(seed)
        scene.setRngSeed(seed)
        empty = np.empty((0, len(names)))
        try:
            path = planner.plan(
                JointConfiguration(names, np.asarray(q_start)),
                JointConfiguration(names, np.asarray(q_goal)),
                [constraint],
            )
        except RuntimeError as exc:
            return PeerCarry(False, str(exc), time.perf_counter() - started, np.empty(0), empty)
        if not path.positions:
            return PeerCarry(False, "no path", time.perf_counter() - started, np.empty(0), empty)
        timed = PathParameterizerTOPPRA(scene, GROUP).generate(
            path, TOPPRAOptions(mode=SplineFittingMode.Hermite)
        )
        elapsed = time.perf_counter() - started
        return PeerCarry(
            True, "", elapsed, np.array(timed.times, dtype=float), np.array(timed.positions, dtype=float)
        )
