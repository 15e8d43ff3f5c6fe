"""The planner: scene -> problem -> (attempt -> search -> choose) -> result.

``plan(scene)`` is ``solve(build_problem(scene))``. :func:`solve` reads as the pipeline:
each attempt (the seeding rule decides the first and the next,
:mod:`planning.pipeline.seeding`) is searched (:mod:`planning.pipeline.search`), its
candidates are timed and verified best first (:mod:`planning.pipeline.choose`), and the
first that passes becomes the :class:`~planning.pipeline.result.PlanResult`. When no
attempt is left and the seeding found a sampling planner's path, that path is followed as it
is (:mod:`planning.pipeline.path_following`) before the plan says "no solution". With a
``time_limit_s`` the stages stop where it passes (:mod:`planning.pipeline.deadline`): the
plan times and verifies what its last search found and, failing that, follows the path
found, with no attempt after it.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import time
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.errors import NoSolutionError, PlanningError
from planning.pipeline.blas_threads import one_blas_thread
from planning.pipeline.choose import Choice, Refusal, choose, verify
from planning.pipeline.deadline import Deadline
from planning.pipeline.metrics import Elapsed
from planning.pipeline.offered import Timing
from planning.pipeline.path_following import follow_path
from planning.pipeline.path_terms import SplinePaths
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.result import PlanResult, assemble
from planning.pipeline.scene import Scene
from planning.pipeline.search import search
from planning.pipeline.seeding import SEEDINGS, NoSeeding
from planning.pipeline.target import Target
from planning.pipeline.torques import held
from planning.search.firefly import FireflyProgress
from planning.search.optimizer import Optimizer, SearchResult
from planning.search.rrt_connect import rrt_connect
from planning.validation import instance_of

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]


@one_blas_thread
def solve(
    problem: Problem,
    progress: Callable[[FireflyProgress], None] | None = None,
    optimizer: Optimizer | None = None,
) -> PlanResult:
    """Search, time and verify a trajectory for ``problem``.

    Args:
        problem: from :func:`~planning.pipeline.problem.build_problem`.
        progress: called after every firefly iteration.
        optimizer: another :class:`~planning.search.optimizer.Optimizer` on the same
            objective and evaluation budget (``fireflies x (iterations + 1)``), searched
            once from a random population; default: the planner's seeded search.

    Raises:
        NoTrajectoryFoundError: no candidate passes the verification (its message names
            the time limit when that stopped the plan).
    """
    started = time.perf_counter()
    instance_of("problem", problem, Problem, "planning.Problem (build_problem(scene))")
    if problem.stands_still:
        return stand_still(problem, started)
    deadline = Deadline.after(problem.scene.planner.time_limit_s, started)
    problem = dataclasses.replace(problem, deadline=deadline)
    seeding = SEEDINGS[problem.scene.planner.seeding] if optimizer is None else NoSeeding()
    attempt = seeding.first(problem)
    while True:
        searched = search(attempt, progress, optimizer)
        search_s = time.perf_counter() - started
        chosen = choose(attempt.problem, searched)
        if isinstance(chosen, Choice):
            elapsed = Elapsed(attempt.problem.build_time_s + time.perf_counter() - started, search_s)
            return assemble(attempt.problem, searched, chosen, elapsed)
        following = None if deadline.passed() else seeding.after(attempt, searched)
        if following is None:
            break
        attempt = following
    stopped = deadline.reason(time.perf_counter() - started) if deadline.passed() else ""
    if attempt.path is None:
        raise chosen.error(attempt.tried, stopped)
    problem, followed = follow_path(attempt.problem, attempt.path)  # the last resort
    if isinstance(followed, Refusal):
        raise chosen.error(attempt.tried, stopped, f"RRT-Connect found a path, but {followed.cause}")
    elapsed = Elapsed(problem.build_time_s + time.perf_counter() - started, search_s)
    return assemble(problem, searched, followed, elapsed)


def stand_still(problem: Problem, started: float) -> PlanResult:
    """The trajectory of a scene whose goal is its start: standing still, verified.

    It lasts the scene's duration, or one IPO period when the duration is free (a trajectory
    needs a time interval; a controller executes nothing shorter).
    """
    scene, objective = problem.scene, problem.objective
    x = np.tile(problem.q_start[problem.moving], scene.planner.waypoints)
    fit = problem.solver.solve(objective.nodes(x[None])[0])
    duration = problem.duration.still_duration(scene.planner.ipo)
    coefficients = np.zeros((1, problem.robot.nq, fit.trajectory.coefficients.shape[2]))
    coefficients[0, :, 0] = problem.q_start  # exactly still (the spline through equal nodes is, to 1e-9)
    trajectory = Trajectory(knots=np.array([0.0, duration]), coefficients=coefficients)
    verification = verify(problem, trajectory, fit)
    if not verification.accepted:  # pragma: no cover - the start was checked clear of the margin
        raise Refusal(f"standing still fails: {'; '.join(verification.problems)}", verification.check).error()
    fitness = float(objective(x[None])[0])
    searched = SearchResult.of_point(x, fitness, 1)
    timing = Timing(trajectory, problem.duration.still_method, fit, False, 0.0)
    choice = Choice(x, objective.nodes(x[None])[0], timing, verification, 1)
    elapsed = Elapsed(problem.build_time_s + time.perf_counter() - started, 0.0)
    return assemble(problem, searched, choice, elapsed)


@one_blas_thread
def plan(
    scene: Scene,
    robot: ck.Robot | None = None,
    progress: Callable[[FireflyProgress], None] | None = None,
    threads: int | None = None,
    optimizer: Optimizer | None = None,
) -> PlanResult:
    """Plan a collision-free, jerk-continuous trajectory for ``scene``.

    ``solve(build_problem(scene, robot, threads), progress, optimizer)``: see
    :func:`~planning.pipeline.problem.build_problem` and :func:`solve`.

    Raises:
        PlanningError: unreachable start or goal, or one inside the margin; bad settings.
        cpr_kin.CprKinError: the robot's URDF or an obstacle is invalid.
        NoTrajectoryFoundError: no candidate passes the verification.
    """
    return solve(build_problem(scene, robot, threads), progress, optimizer)


def warm_up(robot: ck.Robot | None = None) -> float:
    """Compile the numba kernels, or load them from their on-disk cache; seconds spent.

    Planning does it anyway on its first call; this moves the one-time cost (several
    seconds on a new machine, a fraction of a second per process afterwards) out of a plan
    that is timed. It plans the paper case with two fireflies for one iteration and a small
    motion of the robot (the CPR if none is given) in its joint space, runs the search's
    duration estimates with and without the torques, and asks its collision world every
    kind of query once (:func:`_warm_own_motion`).
    """
    from planning.io.bundled import paper_scene

    started = time.perf_counter()
    small = paper_scene(fireflies=2, iterations=1)
    # a search this small may find nothing; a robot of its own may reach the paper's poses
    # inside the paper's crate, or not at all: the motion of its own below warms the rest
    expected: tuple[type[Exception], ...] = (NoSolutionError,)
    if robot is not None:
        expected = (NoSolutionError, PlanningError)
    with contextlib.suppress(*expected):
        plan(small, robot, threads=1)
    _warm_own_motion(robot if robot is not None else ck.load_cpr(), small)
    _warm_sampling()
    return time.perf_counter() - started


def _warm_sampling() -> None:
    """Run RRT-Connect once through a slot in a wall of the unit square: its kernels load.

    The warm-up's own motions are clear on their straight line and draw no sample.
    """

    def beside_the_wall(q: FloatArray) -> BoolArray:
        return np.asarray((np.abs(q[:, 0] - 0.5) > 0.05) | (np.abs(q[:, 1] - 0.5) < 0.1))

    start, goal, ones = np.array([0.1, 0.1]), np.array([0.9, 0.1]), np.ones(2)
    rrt_connect(beside_the_wall, start, goal, 0.0 * ones, ones, ones, np.random.default_rng(0))


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
    # an obstacle at the tool, so that the pairs' bounds leave it in doubt and coal decides
    tool = ck.frame_poses(robot, ends[0, first][None])[0][:3, 3]
    _query_collisions(ck.CollisionWorld(robot, [ck.Obstacle.sphere(0.05, tuple(tool))]), ends[:, first])


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
