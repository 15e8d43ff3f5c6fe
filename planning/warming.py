"""The compiled kernels loaded before a timed plan: :func:`warm_up`.

Planning compiles its numba kernels (or loads them from their on-disk cache) on its first
call in a process; :func:`warm_up` moves that one-time cost out of a plan that is timed, by
planning the bundled paper case small, a motion of the robot's own and a small task of a tool
line and an upright carry. It reads the bundled scene, so it sits above the pipeline, the tasks
and the files (docs/architecture.md).
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import itertools
import time

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.errors import NoSolutionError, PlanningError
from planning.io.bundled import paper_scene
from planning.pipeline.path_terms import SplinePaths
from planning.pipeline.planner import plan, solve
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.pipeline.torques import held
from planning.search.nearest_nodes import INDEXED_FROM
from planning.search.rrt_connect import rrt_connect
from planning.search.rrt_trees import Tree
from planning.task import Move, OrientationConstraint, ToolLine, plan_task
from planning.task.orientation_projection import Projector
from planning.task.orientation_rrt import BATCH, STEP_M
from planning.task.tool_line import BASE_FRAME

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

TASK_LINE_M = (0.0, 0.0, 0.02)
"""The warm-up task's tool line: 2 cm straight up in the base frame [m] (a line a five-joint arm
follows too, as the CPR's column lifts its tool)."""
TASK_ANGLE_RAD = 0.1
"""The warm-up task's upright carry: the tool's z axis within this of the start's [rad]."""


def warm_up(robot: ck.Robot | None = None) -> float:
    """Compile the numba kernels, or load them from their on-disk cache; seconds spent.

    Planning does it anyway on its first call; this moves the one-time cost (several
    seconds on a new machine, a fraction of a second per process afterwards) out of a plan
    that is timed. It plans the paper case with two fireflies for one iteration and a small
    motion of the robot (the paper's, the CPR, if none is given) in its joint space, runs the search's
    duration estimates with and without the torques, and asks its collision world every
    kind of query once and solves its numerical IK once (:func:`_warm_own_motion`); then it
    asks about pairs of the robot's own links as a plan of an arm whose links come near each
    other does, whatever the robot (:func:`_warm_robot_pairs`).
    """
    started = time.perf_counter()
    small = paper_scene(fireflies=2, iterations=1)
    # a search this small may find nothing; a robot of its own may reach the paper's poses
    # inside the paper's crate, or not at all: the motion of its own below warms the rest
    expected: tuple[type[Exception], ...] = (NoSolutionError,)
    if robot is not None:
        expected = (NoSolutionError, PlanningError)
    with contextlib.suppress(*expected):
        plan(small, robot, threads=1)
    own = robot if robot is not None else ck.shared_robot(small.robot_spec())
    _warm_own_motion(own, small)
    _warm_sampling()
    _warm_vertex_witness()
    _warm_robot_pairs(own)
    return time.perf_counter() - started


def _warm_sampling() -> None:
    """Run RRT-Connect once through a slot in a wall of the unit square, ask a large tree: its kernels load.

    The warm-up's own motions are clear on their straight line and draw no sample; only a hard
    problem's trees grow large enough for their k-d tree (:mod:`planning.search.nearest_nodes`).
    """

    def beside_the_wall(q: FloatArray) -> BoolArray:
        return np.asarray((np.abs(q[:, 0] - 0.5) > 0.05) | (np.abs(q[:, 1] - 0.5) < 0.1))

    start, goal, ones = np.array([0.1, 0.1]), np.array([0.9, 0.1]), np.ones(2)
    rrt_connect(beside_the_wall, start, goal, 0.0 * ones, ones, ones, np.random.default_rng(0))
    tree = Tree(start)  # a tree large enough to keep its nodes in a k-d tree (a hard problem's)
    for node in np.random.default_rng(0).random((INDEXED_FROM, 2)):
        tree.add(node, 0)
    tree.nearest(goal, ones)


def _warm_vertex_witness() -> None:
    """Ask the exact meshes' vertex test once (:mod:`cpr_kin.shapes.vertex_witness`): its kernel loads.

    A plan asks it only where a link's exact mesh nears a primitive within a margin, which the
    warm-up's own motions seldom do.
    """
    import pinocchio as pin

    from cpr_kin.shapes.vertex_witness import BOX, vertex_groups

    vertex_groups(np.zeros((1, 3))).within(pin.SE3.Identity(), (BOX, np.ones(3)), 0.0)


def _warm_robot_pairs(robot: ck.Robot) -> None:
    """Ask about pairs of ``robot``'s own links as a plan of an arm with near links does: their kernels load.

    A plan bounds a robot's own pairs (:mod:`cpr_kin.bounds.self_bounds`), looks the near ones
    up in grids over their joints (:mod:`cpr_kin.collision.near_cells`) and asks whether an
    exact mesh holds a shape whole (:mod:`cpr_kin.shapes.held_whole`) only for an arm whose
    links come near each other, which the CPR's never do. Without this, a build of the kernels
    on the CPR alone leaves those kernels to numba, and every process that plans such an arm
    (a Panda) loads all the kernels just in time. Any pairs of geometries on two links serve,
    and a tetrahedron's mesh.
    """
    from cpr_kin.collision.near_cells import NearCells
    from cpr_kin.collision.self_collision import SelfCollision

    geometries = robot.collision_model.geometryObjects
    pairs = tuple(
        (a, b)
        for a, b in itertools.combinations(range(len(geometries)), 2)
        if geometries[a].parentJoint != geometries[b].parentJoint
    )
    q = ck.sampled_configurations(robot.model, 8, np.random.default_rng(0))
    own = SelfCollision(robot.model, robot.collision_model, pairs, [g.name for g in geometries])
    own.violated(q, 0.01)
    own.distances(q)
    for pair in pairs:
        cells = NearCells(robot.model, robot.collision_model, [pair])
        if cells.grids is not None:
            cells.states(q, [0.01])
            break
    _warm_held_whole()


def _warm_held_whole() -> None:
    """Ask whether a tetrahedron's exact mesh holds a sphere whole (``held_whole.may_hold``)."""
    import coal
    import pinocchio as pin

    from cpr_kin.shapes.exact_meshes import ExactMesh
    from cpr_kin.shapes.held_whole import inner_points, may_hold
    from cpr_kin.shapes.mesh_topology import mesh_topology

    corners = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, 0.1]])  # [m]
    bvh = coal.BVHModelOBBRSS()
    bvh.beginModel(4, 4)
    bvh.addVertices(corners)
    bvh.addTriangles(np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]))
    bvh.endModel()
    made = mesh_topology(bvh, b"the warm-up's tetrahedron")
    tetrahedron = ExactMesh(
        0, bvh, pin.SE3.Identity(), 0.0, made.triangles, made.piece_points, made.hull_planes, made.corners
    )
    at = pin.SE3.Identity()
    may_hold(tetrahedron, inner_points(coal.Sphere(0.01), None), at, at)


def _warm_own_motion(robot: ck.Robot, small: Scene) -> None:
    """Plan a small motion of ``robot`` in its joint space, run its estimates, ask every query.

    The paper's small search may find nothing (its timing then never runs), and a robot of
    its own may reach the paper's poses inside the paper's crate, or not at all. The motion
    starts at the sampled configuration farthest from itself that the motors can hold still.
    """
    world = ck.CollisionWorld(robot, [ck.Obstacle.box((0.1, 0.1, 0.1), (0.0, 0.0, 10.0))])
    q = ck.sampled_configurations(robot.model, 64, np.random.default_rng(0))
    if world.self_collision:  # the configuration farthest from itself first
        q = q[np.argsort(-world.self_collision.distances(q)[0])]
    ends = np.stack([q, np.minimum(robot.model.upperPositionLimit, q + 0.1)])
    # ends the motors can hold still, or the plan stops before its timing is compiled
    dynamics = ck.robot_dynamics(robot)
    first = int(np.argmax(held(dynamics, ends[0]) & held(dynamics, ends[1])))
    start, goal = Target(q=tuple(ends[0, first])), Target(q=tuple(ends[1, first]))
    own = dataclasses.replace(
        small, start=start, goal=goal, obstacles=world.obstacles, self_margin=0.0, duration=None
    )
    with contextlib.suppress(PlanningError, NoSolutionError):  # what ran, ran
        problem = build_problem(own, robot, threads=1)
        _estimate_durations(problem, dynamics)  # before the plan, which may find nothing
        solve(problem)
    _warm_task(own, robot)
    # the numerical IK's descent, to the goal's tool pose from the start (a pose goal's)
    goal_tool = ck.frame_poses(robot, ends[1, first][None])[0]
    with contextlib.suppress(ck.IkMissError):
        ck.solve_ik(robot, ck.IkTarget(goal_tool[:3, 3], goal_tool[:3, :3]), ends[0, first])
    # an obstacle at the tool, so that the pairs' bounds leave it in doubt and coal decides
    tool = ck.frame_poses(robot, ends[0, first][None])[0][:3, 3]
    _query_collisions(ck.CollisionWorld(robot, [ck.Obstacle.sphere(0.05, tuple(tool))]), ends[:, first])


def _warm_task(own: Scene, robot: ck.Robot) -> None:
    """Plan a small task from ``own``'s start: a tool line, then an upright carry back to the start.

    A task's kernels are its own (the line's walk, the projection onto an orientation
    constraint and the walk on its manifold, the B-spline through a path's samples): they load,
    or a process that plans a task would compile them (:mod:`planning.ahead_of_time` exports
    what the warm-up calls).
    """
    scene = Scene(start=own.start, goal=own.start, obstacles=own.obstacles, self_margin=0.0, name="warm-up")
    constraint = OrientationConstraint(("x", "y"), TASK_ANGLE_RAD)
    with contextlib.suppress(PlanningError, NoSolutionError):
        line = ToolLine(by=TASK_LINE_M, offset_frame=BASE_FRAME)
        plan_task(scene, [line, Move(goal=own.start, constraint=constraint)], robot, threads=1)
    # the carry above bends the planner's path; a carry that plans on the manifold walks it
    q = np.asarray(own.start.configuration(robot), dtype=float)
    projector = Projector(robot, robot.tcp_frame, constraint, ck.frame_poses(robot, q)[:3, :3])
    projector.steps(q, q + 0.01, STEP_M, np.inf, BATCH, ck.motion_radii(robot))


def _estimate_durations(problem: Problem, dynamics: ck.Dynamics) -> None:
    """Run the search's estimates of ``problem``'s straight line: durations, the averages' foresight.

    The duration estimates kinematic and torque-limited; the samples the choice's foresight
    averages (:func:`~planning.pipeline.choose.foreseen_clear`). A plan keeps the torques in
    its estimate only where they bind on its straight line
    (:func:`~planning.pipeline.torques.search_torque`), which a warm-up motion seldom does;
    the choice foresees the averages only behind a feasible best.
    """
    objective = problem.objective
    paths = objective.paths
    if not isinstance(paths, SplinePaths):  # point to point: no estimate
        return
    samples = paths(objective.nodes(objective.straight_line())).samples
    for torque in (None, dynamics):
        estimate = copy.copy(paths)
        estimate.torque = torque
        estimate.durations(samples)
        estimate.averaged(samples)  # the kinematic one's; None where torque-limited


def _query_collisions(world: ck.CollisionWorld, q: FloatArray) -> None:
    """Ask ``world`` every kind of query once at configurations ``q``, its robot's own pairs too.

    A compiled kernel loads from its cache on its first call in a process.
    """
    world.margin_violated(q, 0.01)
    world.min_clearance_batch(q)
    if world.self_collision:
        world.self_collision.violated(q, 0.01)
        world.self_collision.distances(q)
