"""The planner: scene -> problem -> (attempt -> search -> choose) -> result.

``plan(scene)`` is ``solve(build_problem(scene))``. A robot whose concave links are checked
on their exact meshes (:mod:`cpr_kin.shapes.exact_pairs`) is planned on their convex hulls first,
which contain them and cost no triangle query (:func:`~planning.pipeline.hulls_first.on_hulls`,
with a share of the samples and of a time limit), and on the meshes where the hulls find no
trajectory (RRT-Connect going on with the trees the hulls grew). :func:`solve` reads as the pipeline:
each attempt (the seeding rule decides the first and the next,
:mod:`planning.pipeline.seeding`) is searched (:mod:`planning.pipeline.search`), its
candidates are timed and verified best first (:mod:`planning.pipeline.choose`), and the
first that passes becomes the :class:`~planning.pipeline.result.PlanResult`. When no
attempt is left and the seeding found a sampling planner's path, that path is followed
closely (:mod:`planning.pipeline.path_following`) before the plan says "no solution". With a
``time_limit_s`` the stages stop where it passes (:mod:`planning.pipeline.deadline`): the
plan times and verifies what its last search found and, failing that, follows the path
found, with no attempt after it, while the time limit has not passed.
"""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable

import numpy as np

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.errors import NoTrajectoryFoundError
from planning.pipeline.blas_threads import one_blas_thread
from planning.pipeline.choose import Choice, Refusal, beyond_margin, choose, verify
from planning.pipeline.deadline import Deadline
from planning.pipeline.hulls_first import HULLS_SHARE, on_hulls, shared_trees
from planning.pipeline.metrics import Elapsed
from planning.pipeline.offered import Timing
from planning.pipeline.path_following import follow_path
from planning.pipeline.problem import Problem, build_problem
from planning.pipeline.result import PlanResult, assemble
from planning.pipeline.scene import Scene
from planning.pipeline.search import search
from planning.pipeline.seeding import SEEDINGS, NoSeeding
from planning.search.firefly import FireflyProgress
from planning.search.optimizer import Optimizer, SearchResult
from planning.validation import instance_of


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
            (The hulls first, :func:`~planning.pipeline.hulls_first.on_hulls`, with the planner's own.)

    Raises:
        NoTrajectoryFoundError: no candidate passes the verification (its message names
            the time limit when that stopped the plan).
    """
    started = time.perf_counter()
    instance_of("problem", problem, Problem, "planning.Problem (build_problem(scene))")
    if problem.stands_still:
        return stand_still(problem, started)
    deadline = Deadline.after(problem.scene.planner.time_limit_s, started)
    hulls = on_hulls(problem) if optimizer is None else None
    if hulls is not None:
        grown = shared_trees(hulls, problem)  # the hulls' trees, for the meshes' draw to go on with
        hulls, problem = (dataclasses.replace(p, grown=grown) for p in (hulls, problem))
        limit_s = problem.scene.planner.time_limit_s
        share = Deadline.after(None if limit_s is None else limit_s * HULLS_SHARE, started)
        # a check cut where the plan's are; a search that found a feasible candidate goes on to its end
        share = dataclasses.replace(share, cut_at_s=deadline.cut_at_s, feasible_at_s=deadline.at_s)
        try:
            return _solved(hulls, share, started, progress, optimizer, deadline)
        except NoTrajectoryFoundError:
            pass  # the meshes' turn, in the time left
    return _solved(problem, deadline, started, progress, optimizer, deadline)


def _solved(
    problem: Problem,
    deadline: Deadline,
    started: float,
    progress: Callable[[FireflyProgress], None] | None,
    optimizer: Optimizer | None,
    last_resort_by: Deadline,
) -> PlanResult:
    """:func:`solve`'s pipeline on ``problem`` by ``deadline`` (its clock started at ``started`` [s]).

    The last resort runs only before ``last_resort_by``: the plan's own deadline, which
    ``deadline`` is where it is a share of it (the hulls').
    """
    problem = dataclasses.replace(problem, deadline=deadline)
    seeding = SEEDINGS[problem.scene.planner.seeding] if optimizer is None else NoSeeding()
    attempt = seeding.first(problem)
    while True:
        searched = search(attempt, progress, optimizer)
        search_s = time.perf_counter() - started
        # a best deeper inside a margin than a step fails its check, which only says why: where
        # another attempt follows, it is not run (on a Fetch among shelves, seconds)
        deepest = beyond_margin(attempt.problem, searched)
        hopeless = deepest is not None
        following = None if not hopeless or deadline.passed() else seeding.after(attempt, searched)
        if following is None:
            chosen = choose(attempt.problem, searched, deepest)
            if isinstance(chosen, Choice):
                elapsed = Elapsed(attempt.problem.build_time_s + time.perf_counter() - started, search_s)
                return assemble(attempt.problem, searched, chosen, elapsed)
            following = None if hopeless or deadline.passed() else seeding.after(attempt, searched)
            if following is None:
                break
        attempt = following
    stopped = deadline.reason() if deadline.passed() else ""
    if attempt.path is None:
        raise chosen.error(attempt.tried, stopped)
    if last_resort_by.passed():
        found = "RRT-Connect found a path, but the time limit passed before it was followed"
        raise chosen.error(attempt.tried, last_resort_by.reason(), found)
    by_the_plans = dataclasses.replace(attempt.problem, deadline=last_resort_by)  # not the hulls' share
    problem, followed = follow_path(by_the_plans, attempt.path)  # the last resort
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
