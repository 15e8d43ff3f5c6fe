"""Build a planning problem from a scene: robot, collision world, motion, duration rule, objective.

:func:`build_problem` does everything that depends only on the scene, and refuses bad input
before any search starts: it loads the robot, builds the collision world, solves and
checks the start and goal, picks the moving joints, chooses the duration rule (fixed or
free, :mod:`planning.pipeline.timing`) and prepares the spline solver and the waypoint
objective. :func:`planning.pipeline.planner.solve` then searches, times and verifies;
``cpr-plan check`` and the peer planners use the same problem.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.spline import SepticSplineSolver, uniform_knots
from planning.errors import PlanningError
from planning.pipeline.deadline import Deadline
from planning.pipeline.endpoints import endpoint
from planning.pipeline.motion import Motion
from planning.pipeline.objective import PathRules, WaypointObjective
from planning.pipeline.scene import Scene
from planning.pipeline.settings import VERIFY_STEP_RANGE_M
from planning.pipeline.timing import FixedDuration, FreeDuration, duration_rule
from planning.pipeline.torques import GravityLimit, gravity_limit, scene_dynamics, search_torque
from planning.search.rrt_trees import GrownTrees
from planning.validation import instance_of

FloatArray = NDArray[np.float64]

SAME_POSE_TOLERANCE = 1e-9
"""Start and goal closer than this in every joint [rad or m] are one pose: the plan stands still."""


@dataclass(frozen=True)
class Problem:
    """A scene made ready to solve.

    Attributes:
        scene: the scene.
        robot: the robot it plans for.
        world: the robot among the scene's obstacles.
        motion: start and goal (reachable, clear of the margin) and the moving joints.
        duration: the scene's duration rule (fixed or free).
        solver: the septic spline solver on the search's knots: the trajectory's spline when
            the scene fixes the duration, else the geometric path's.
        objective: the waypoint objective the search minimises.
        dynamics: the robot's torques with the scene's payload, and their limits.
        gravity: where gravity may exceed an effort limit between start and goal, the rule
            that every configuration of a path be one the motors can hold still (the
            search's and the sampling planner's; :func:`~planning.pipeline.torques.gravity_limit`);
            ``None`` elsewhere.
        build_time_s: wall time of :func:`build_problem` [s].
        deadline: when its plan must stop (:func:`~planning.pipeline.planner.solve` sets it
            from the planner's ``time_limit_s``; default: never).
        grown: where RRT-Connect's draw for its plan finds and leaves the trees of a draw that
            found no path (:func:`~planning.pipeline.planner.solve` sets one for the hulls and
            the meshes of a plan; default: none, each draw grows its own).
    """

    scene: Scene
    robot: ck.Robot = field(repr=False)
    world: ck.CollisionWorld = field(repr=False)
    motion: Motion
    duration: FixedDuration | FreeDuration
    solver: SepticSplineSolver = field(repr=False)
    objective: WaypointObjective = field(repr=False)
    dynamics: ck.Dynamics = field(repr=False)
    gravity: GravityLimit | None = field(default=None, repr=False)
    build_time_s: float = 0.0
    deadline: Deadline = field(default_factory=Deadline)
    grown: GrownTrees | None = field(default=None, repr=False)

    @property
    def q_start(self) -> FloatArray:
        """Start configuration [rad, m]."""
        return self.motion.q_start

    @property
    def q_goal(self) -> FloatArray:
        """Goal configuration [rad, m]."""
        return self.motion.q_goal

    @property
    def moving(self) -> NDArray[np.intp]:
        """Indices of the joints the waypoints move."""
        return self.motion.moving

    def configurations(self, moving_q: FloatArray) -> FloatArray:
        """``(k, nq)`` configurations from the moving joints' values ``moving_q`` ``(k, moving)``.

        The other joints held where they start [rad, m].
        """
        if self.motion.moves_every_joint:
            return np.array(moving_q, dtype=float)
        full = np.repeat(self.q_start[None], len(moving_q), axis=0)
        full[:, self.moving] = moving_q
        return full

    @property
    def stands_still(self) -> bool:
        """The goal is the start (within :data:`SAME_POSE_TOLERANCE` in every joint)."""
        return bool(np.allclose(self.q_start, self.q_goal, rtol=0.0, atol=SAME_POSE_TOLERANCE))


def moving_joints(robot: ck.Robot, scene: Scene, q_start: FloatArray, q_goal: FloatArray) -> NDArray[np.intp]:
    """Indices of the joints a plan moves.

    ``scene.planner.moving_joints``, or every joint but the robot's wrist joints
    (:attr:`cpr_kin.Robot.wrist_joints`, a preset's) whose start and goal
    values agree.

    Raises:
        PlanningError: a named joint the robot does not plan, or none named.
    """
    names = scene.planner.moving_joints
    if names is None:
        names = tuple(
            n
            for i, n in enumerate(robot.joint_names)
            if n not in robot.wrist_joints or not np.isclose(q_start[i], q_goal[i])
        )
    unknown = [n for n in names if n not in robot.joint_names]
    if unknown:
        raise PlanningError(
            f"planner.moving_joints names {unknown}, not among the robot's planned joints "
            f"{list(robot.joint_names)}"
        )
    if not names:
        raise PlanningError("moving_joints is empty; name at least one joint the waypoints may move")
    return np.array([robot.limits.index(n) for n in names], dtype=np.intp)


def scene_robot(scene: Scene, robot: ck.Robot) -> ck.Robot:
    """``robot`` carrying ``scene``'s payload: its shape, if it has one, checked as the robot's.

    Raises:
        PlanningError: the payload's frame is not the robot's.
    """
    try:
        return ck.carrying(robot, scene.payload)
    except ck.CprKinError as exc:
        raise PlanningError(f"payload: {exc}") from None


def scene_world(scene: Scene, robot: ck.Robot, threads: int | None = None) -> ck.CollisionWorld:
    """``robot`` among ``scene``'s obstacles, its pairs held as the scene holds them.

    The scene's ``allowed_collisions`` may touch; a pair close by design is held to contact
    only where the scene's self margin exceeds its gap (:mod:`cpr_kin.bounds.close_pairs`).
    ``threads``: those of the parallel collision checks (default: one on 2 cores, two on more).

    Raises:
        PlanningError: ``allowed_collisions`` names a link the robot does not have (a typo
            would leave the pair checked, silently).
    """
    unknown = sorted({n for pair in scene.allowed_collisions for n in pair if not robot.model.existFrame(n)})
    if unknown:
        links = sorted({g.link for g in robot.geometries})
        raise PlanningError(f"allowed_collisions names {unknown}, not links of the robot; its links: {links}")
    return ck.CollisionWorld(
        robot,
        scene.obstacles,
        num_threads=threads,
        allowed_pairs=scene.allowed_collisions,
        self_margin_m=scene.self_margin,
    )


def build_problem(
    scene: Scene,
    robot: ck.Robot | None = None,
    threads: int | None = None,
    goal_test: Callable[[FloatArray], Callable[[FloatArray], bool]] | None = None,
) -> Problem:
    """Everything about ``scene`` that a search needs, checked.

    Args:
        scene: the problem and its settings.
        robot: a loaded robot (default: ``scene.robot`` loaded; a scene that names none needs one).
        threads: threads of the parallel collision checks (default: one on 2 cores, two on
            more); a batch that plans scenes in parallel processes gives each 1.
        goal_test: from the start's configuration, a test of a ``tcp`` or ``pose`` goal's IK
            solutions: the one reached soonest from the start of those that pass it is chosen where one does
            (:func:`~planning.pipeline.endpoints.endpoint`).

    Raises:
        PlanningError: a bad start or goal, or one inside a margin; a fixed duration
            shorter than the limits allow; bad settings.
        TargetOutOfReachError: a ``tcp`` or ``pose`` start or goal no configuration reaches.
        PayloadTooHeavyError: the motors cannot hold the start or goal still.
        cpr_kin.CprKinError: the robot's URDF or an obstacle is invalid.
    """
    started = time.perf_counter()
    instance_of("scene", scene, Scene, "planning.Scene (load_scene, paper_scene, Scene(start=..., goal=...))")
    if robot is not None:
        instance_of("robot", robot, ck.Robot, "cpr_kin.Robot (load_robot, load_cpr), or None: the scene's")
    robot = scene_robot(scene, robot or ck.shared_robot(scene.robot_spec()))
    world = scene_world(scene, robot, threads)
    dynamics = scene_dynamics(robot, scene)
    q_start = endpoint(world, scene, "start", dynamics=dynamics)
    preferred = None if goal_test is None else goal_test(q_start)
    q_goal = endpoint(world, scene, "goal", seed_q=q_start, dynamics=dynamics, preferred=preferred)
    motion = Motion(q_start, q_goal, moving_joints(robot, scene, q_start, q_goal))
    duration = duration_rule(scene.duration, search_torque(robot, dynamics, q_start, q_goal))
    if isinstance(duration, FixedDuration):
        duration.check_reachable(robot, q_start, q_goal, rest_ends=scene.spline.ends == "rest")
    gravity = gravity_limit(robot, dynamics, q_start, motion.moving)
    solver, objective = _search_space(scene, world, motion, duration, gravity)
    return Problem(
        scene=scene,
        robot=robot,
        world=world,
        motion=motion,
        duration=duration,
        solver=solver,
        objective=objective,
        dynamics=dynamics,
        gravity=gravity,
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
    solver, objective = _search_space(scene, problem.world, problem.motion, problem.duration, problem.gravity)
    return dataclasses.replace(
        problem,
        scene=scene,
        solver=solver,
        objective=objective,
        build_time_s=problem.build_time_s + time.perf_counter() - started,
    )


def finer_step_m(problem: Problem) -> float:
    """The certified step [m] tried where the margins plus ``verify_step_m`` leave no path.

    The settings' :attr:`~planning.pipeline.settings.PlannerSettings.finer_verify_step_m`
    (``finer_step`` of the step); where the start or goal lies no farther than that beyond
    its margin (a grasp a fraction of a millimetre from its shelf, a wrist as close to its
    own forearm), half its clearance beyond the margin, so that both ends keep the margins
    plus the step, as every configuration of a path must. At least ``VERIFY_STEP_RANGE_M[0]``.
    """
    scene, world = problem.scene, problem.world
    ends = np.stack([problem.q_start, problem.q_goal])
    excess = float(world.min_clearance_batch(ends)[0].min()) - scene.safety_margin
    if world.self_collision:
        excess = min(excess, float(world.self_collision.distances(ends)[0].min()) - scene.self_margin)
    finer = scene.planner.finer_verify_step_m
    return finer if excess > finer else max(excess / 2, VERIFY_STEP_RANGE_M[0])


def _search_space(
    scene: Scene,
    world: ck.CollisionWorld,
    motion: Motion,
    duration: FixedDuration | FreeDuration,
    gravity: GravityLimit | None,
) -> tuple[SepticSplineSolver, WaypointObjective]:
    """The spline solver on the search's knots and the waypoint objective (held to ``gravity``, if any)."""
    segments = scene.planner.waypoints + 1
    # the spline on the search's knots: the trajectory itself when the scene fixes the duration,
    # else the geometric path that the timing runs as fast as the limits allow
    solver = SepticSplineSolver(uniform_knots(segments, duration.nominal_duration(segments)), scene.spline)
    rules = PathRules(scene.safety_margin, scene.self_margin, gravity)
    objective = WaypointObjective(world, motion, rules, scene.planner, solver, duration)
    return solver, objective
