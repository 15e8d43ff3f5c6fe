"""Build a planning problem from a scene: robot, collision world, endpoints, objective.

:func:`build_problem` does everything that depends only on the scene, and refuses bad input
before any search starts: it loads the robot, builds the collision world, solves and
checks the start and goal, picks the moving joints and prepares the spline solver and the
waypoint objective. :func:`planning.planner.solve` then searches, times and verifies;
``cpr-plan check`` and the peer planners use the same problem.
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SepticSplineSolver, uniform_knots
from planning.errors import PlanningError
from planning.objective import WaypointObjective
from planning.scene import Scene

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Problem:
    """A scene made ready to solve.

    Attributes:
        scene: the scene.
        robot: the robot it plans for.
        world: the robot among the scene's obstacles.
        q_start: start configuration [rad, m], reachable and clear of the margin.
        q_goal: goal configuration [rad, m], likewise.
        moving: indices of the joints the waypoints move.
        solver: the septic spline solver on the search's knots: the trajectory's spline when
            the scene fixes the duration, else the geometric path's.
        objective: the waypoint objective the search minimises.
        build_time_s: wall time of :func:`build_problem` [s].
    """

    scene: Scene
    robot: ck.Robot = field(repr=False)
    world: ck.CollisionWorld = field(repr=False)
    q_start: FloatArray
    q_goal: FloatArray
    moving: NDArray[np.intp]
    solver: SepticSplineSolver = field(repr=False)
    objective: WaypointObjective = field(repr=False)
    build_time_s: float = 0.0


def moving_joints(robot: ck.Robot, scene: Scene, q_start: FloatArray, q_goal: FloatArray) -> NDArray[np.intp]:
    """Indices of the joints a plan moves.

    ``scene.planner.moving_joints``, or every joint but the robot's wrist joints
    (:attr:`cpr_kin.Robot.wrist_joints`; the CPR's theta4 and theta5) whose start and goal
    values agree.
    """
    names = scene.planner.moving_joints
    if names is None:
        names = tuple(
            n
            for i, n in enumerate(robot.joint_names)
            if n not in robot.wrist_joints or not np.isclose(q_start[i], q_goal[i])
        )
    if not names:
        raise PlanningError("moving_joints is empty; name at least one joint the waypoints may move")
    return np.array([robot.limits.index(n) for n in names], dtype=np.intp)


def endpoint(robot: ck.Robot, world: ck.CollisionWorld, scene: Scene, label: str) -> FloatArray:
    """The configuration of the scene's start or goal; refused if unreachable or inside the margin."""
    target = scene.start if label == "start" else scene.goal
    try:
        q = target.configuration(robot)
    except ck.CprKinError as exc:
        raise PlanningError(f"{label} is not reachable: {exc}") from None
    clearance = world.clearance(q)
    closest = clearance.closest
    if closest is not None and clearance.min_clearance_m < scene.safety_margin:
        raise PlanningError(
            f"{label} q = {np.round(q, 4).tolist()} is inside the safety margin: {closest.robot_geometry} "
            f"is {clearance.min_clearance_m:.3f} m from obstacle '{closest.obstacle}' "
            f"(margin {scene.safety_margin} m)"
        )
    return q


def build_problem(scene: Scene, robot: ck.Robot | None = None, threads: int | None = None) -> Problem:
    """Everything about ``scene`` that a search needs, checked.

    Args:
        scene: the problem and its settings.
        robot: a loaded robot (default: load ``scene.robot`` or the bundled CPR).
        threads: threads of the parallel collision checks (default: up to 2); a batch that
            plans scenes in parallel processes gives each 1.

    Raises:
        PlanningError: unreachable start or goal, or one inside the margin; bad settings.
        cpr_kin.CprKinError: the robot's URDF or an obstacle is invalid.
    """
    started = time.perf_counter()
    robot = robot or ck.load_cpr(scene.robot)
    world = ck.CollisionWorld(robot, scene.obstacles, num_threads=threads)
    q_start = endpoint(robot, world, scene, "start")
    q_goal = endpoint(robot, world, scene, "goal")
    moving = moving_joints(robot, scene, q_start, q_goal)
    solver, objective = _search(scene, world, q_start, q_goal, moving)
    return Problem(
        scene=scene,
        robot=robot,
        world=world,
        q_start=q_start,
        q_goal=q_goal,
        moving=moving,
        solver=solver,
        objective=objective,
        build_time_s=time.perf_counter() - started,
    )


def with_planner(problem: Problem, **changes: Any) -> Problem:
    """``problem`` with planner settings changed (same world and endpoints), e.g. ``waypoints=5``.

    Raises:
        PlanningError: an unknown setting, or a value the settings refuse.
    """
    settings = problem.scene.planner.updated(**changes)
    if settings == problem.scene.planner:
        return problem
    started = time.perf_counter()
    scene = dataclasses.replace(problem.scene, planner=settings)
    solver, objective = _search(scene, problem.world, problem.q_start, problem.q_goal, problem.moving)
    return dataclasses.replace(
        problem,
        scene=scene,
        solver=solver,
        objective=objective,
        build_time_s=problem.build_time_s + time.perf_counter() - started,
    )


def _search(
    scene: Scene, world: ck.CollisionWorld, q_start: FloatArray, q_goal: FloatArray, moving: NDArray[np.intp]
) -> tuple[SepticSplineSolver, WaypointObjective]:
    """The spline solver on the search's knots and the waypoint objective."""
    segments = scene.planner.waypoints + 1
    nominal_duration = scene.duration if scene.duration is not None else float(segments)
    # the spline on the search's knots: the trajectory itself when the scene fixes the duration,
    # else the geometric path that the timing runs as fast as the limits allow
    solver = SepticSplineSolver(uniform_knots(segments, nominal_duration), scene.spline)
    objective = WaypointObjective(
        world,
        q_start,
        q_goal,
        moving,
        scene.safety_margin,
        scene.planner,
        solver,
        timed=scene.duration is not None,
    )
    return solver, objective
