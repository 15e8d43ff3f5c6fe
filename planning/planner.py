"""The planner: problem -> waypoint search -> septic spline -> timing -> verified trajectory.

``plan(scene)`` is ``solve(build_problem(scene))``: :func:`~planning.problem.build_problem`
checks the scene and prepares the objective, :func:`solve` searches, times and verifies.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.candidates import first_verified, verify
from planning.curves.spline import SplineFit
from planning.curves.trajectory import Trajectory
from planning.errors import NoSolutionError, NoTrajectoryFoundError
from planning.metrics import Metrics, measure
from planning.objective import Breakdown
from planning.problem import Problem, build_problem, with_planner
from planning.scene import MAX_FITNESS_SAMPLES, Scene
from planning.search.firefly import FireflyProgress, firefly_minimize
from planning.search.optimizer import Optimizer, SearchResult
from planning.search.refinement import refine_search
from planning.seeding import seed_search
from planning.timing import Timing

FloatArray = NDArray[np.float64]

RETRIES = 2
"""With ``seeding: paths``, how many times a failed search is tried again: with more
waypoints when no candidate was feasible, with twice the fitness samples when feasible ones
failed the certified check (a violation between two samples escaped the fitness)."""
SAME_POSE_TOLERANCE = 1e-9
"""Start and goal closer than this in every joint [rad or m] are one pose: the plan stands still."""


@dataclass(frozen=True)
class PlanResult:
    """A planned, verified trajectory with everything that produced it.

    Attributes:
        problem: the problem solved (scene, robot, collision world, objective).
        waypoints: ``(p + 2, nq)`` start, intermediate waypoints, goal [rad, m].
        trajectory: the timed septic spline.
        spline: the spline fit (on the nominal knots, before timing).
        time_scale: the trajectory's duration over the spline's nominal one (the uniform
            time scaling, unless the timing is ``fastest``).
        metrics: figures of the result.
        breakdown: the chosen candidate's fitness terms.
        optimiser: the search's run (history, population).
        verification: the certified continuous check of the trajectory.
    """

    problem: Problem = field(repr=False)
    waypoints: FloatArray
    trajectory: Trajectory
    spline: SplineFit = field(repr=False)
    time_scale: float
    metrics: Metrics
    breakdown: Breakdown = field(repr=False)
    optimiser: SearchResult = field(repr=False)
    verification: ck.CurveCheck = field(repr=False)

    @property
    def scene(self) -> Scene:
        """The scene planned."""
        return self.problem.scene

    @property
    def robot(self) -> ck.Robot:
        """The robot planned for."""
        return self.problem.robot

    @property
    def joint_names(self) -> tuple[str, ...]:
        """Joint order of every array."""
        return self.problem.robot.joint_names


def solve(
    problem: Problem,
    progress: Callable[[FireflyProgress], None] | None = None,
    optimizer: Optimizer | None = None,
) -> PlanResult:
    """Search, time and verify a trajectory for ``problem``.

    Steps: firefly search of the waypoints on the problem's objective
    (:mod:`planning.objective`), its best refined by a CMA-ES (``refine: cma``); septic
    spline through start, waypoints and goal on ``p + 1`` uniform segments; timing
    (:mod:`planning.timing`: the scene's duration, stretched if it breaks a velocity,
    acceleration or jerk limit; or, with the duration free, as fast as the limits allow
    along the path, with narrowed and uniform timings as the fallbacks); certified
    continuous verification of the whole trajectory against the margin. If the best
    candidate fails the verification, the refinement's earlier points and the final
    population's other feasible candidates are tried
    (:func:`~planning.candidates.first_verified` says in which order).

    Args:
        problem: from :func:`~planning.problem.build_problem`.
        progress: called after every firefly iteration.
        optimizer: another :class:`~planning.search.optimizer.Optimizer` on the same
            objective and evaluation budget (``fireflies x (iterations + 1)``); default:
            the firefly.

    Raises:
        NoTrajectoryFoundError: no candidate passes the verification.
    """
    started = time.perf_counter()
    if np.allclose(problem.q_start, problem.q_goal, rtol=0.0, atol=SAME_POSE_TOLERANCE):
        return _stay_put(problem, started)
    escalate = optimizer is None and problem.scene.planner.seeding == "paths"
    path, widen = None, False
    for attempt in range(1 + (RETRIES if escalate else 0)):
        seeds = seed_search(problem, widen, path) if escalate else None
        searched = problem if seeds is None else seeds.problem
        path = None if seeds is None else seeds.path
        result = _search(searched, progress, optimizer, None if seeds is None else seeds.candidates)
        optimiser_time = time.perf_counter() - started
        try:
            x, nodes, timing, verification, tried = first_verified(searched, result)
            break
        except NoTrajectoryFoundError:
            if attempt == RETRIES or not escalate:
                raise
        # no candidate feasible: more waypoints; feasible ones failed the certified check: a
        # violation between two samples escaped the fitness, so check twice as many
        widen = result.fitness > searched.objective.t_max
        samples = searched.scene.planner.fitness_samples
        problem = (
            searched
            if widen
            else with_planner(searched, fitness_samples=min(2 * samples, MAX_FITNESS_SAMPLES))
        )
    problem = searched
    objective = problem.objective
    trajectory, fit = timing.trajectory, timing.fit
    breakdown = objective.breakdown(x[None])
    metrics = measure(
        problem.robot,
        trajectory,
        verification.check,
        fit.max_node_deviation,
        breakdown,
        result,
        (problem.build_time_s + time.perf_counter() - started, optimiser_time),
        tried,
        timing,
    )
    return PlanResult(
        problem=problem,
        waypoints=nodes,
        trajectory=trajectory,
        spline=fit,
        time_scale=trajectory.duration / fit.trajectory.duration,
        metrics=metrics,
        breakdown=breakdown,
        optimiser=result,
        verification=verification.check,
    )


def _search(
    problem: Problem,
    progress: Callable[[FireflyProgress], None] | None,
    optimizer: Optimizer | None,
    seeds: FloatArray | None,
) -> SearchResult:
    """The firefly (from ``seeds`` and a random population) or ``optimizer``.

    With ``refine: cma`` and a feasible best, the firefly's best is refined by a CMA-ES
    (:func:`~planning.search.refinement.refine_search`) within the rest of the budget,
    drawing on the same generator after the firefly, until ``refine_stall`` generations
    in a row have stalled within :data:`~planning.search.refinement.NEAR_BOUND` times the
    objective's lower bound (0: to the budget).
    """
    objective, settings = problem.objective, problem.scene.planner
    rng = np.random.default_rng(settings.seed)
    if optimizer is not None:
        return optimizer(objective, objective.lower, objective.upper, settings.firefly.evaluations, rng)
    found = firefly_minimize(
        objective,
        objective.lower,
        objective.upper,
        settings.firefly,
        rng,
        progress,
        seeds,
        stall_below=objective.t_max,  # stop early only once a candidate is feasible
    )
    if settings.refine == "none" or found.fitness > objective.t_max:
        return found
    budget = settings.firefly.evaluations - found.evaluations
    return refine_search(
        objective,
        objective.lower,
        objective.upper,
        found,
        budget,
        rng,
        stall_generations=settings.refine_stall,
        lower_bound=objective.lower_bound,
    )


def _stay_put(problem: Problem, started: float) -> PlanResult:
    """The trajectory of a scene whose goal is its start: standing still, verified.

    It lasts the scene's duration, or one IPO period when the duration is free (a trajectory
    needs a time interval; a controller executes nothing shorter).
    """
    scene, objective = problem.scene, problem.objective
    x = np.tile(problem.q_start[problem.moving], scene.planner.waypoints)
    fit = problem.solver.solve(objective.nodes(x[None])[0])
    duration = scene.duration if scene.duration is not None else scene.planner.ipo
    scale = duration / fit.trajectory.duration
    coefficients = np.zeros((1, problem.robot.nq, fit.trajectory.coefficients.shape[2]))
    coefficients[0, :, 0] = problem.q_start  # exactly still (the spline through equal nodes is, to 1e-9)
    trajectory = Trajectory(knots=np.array([0.0, duration]), coefficients=coefficients)
    verification = verify(problem, trajectory, fit)
    if not verification.accepted:  # pragma: no cover - the start was checked clear of the margin
        raise NoTrajectoryFoundError(
            f"standing still fails: {'; '.join(verification.problems)}", verification.check
        )
    breakdown = objective.breakdown(x[None])
    fitness = float(breakdown.fitness[0])
    search = SearchResult(
        x=x,
        fitness=fitness,
        evaluations=1,
        best_history=np.array([fitness]),
        mean_history=np.array([fitness]),
        evaluation_history=np.array([1], dtype=np.int64),
        population=x[None],
        population_fitness=np.array([fitness]),
    )
    elapsed = problem.build_time_s + time.perf_counter() - started
    metrics = measure(
        problem.robot,
        trajectory,
        verification.check,
        fit.max_node_deviation,
        breakdown,
        search,
        (elapsed, 0.0),
        1,
        Timing(trajectory, "fixed" if scene.duration is not None else "fastest", fit, False, 0.0),
    )
    return PlanResult(
        problem=problem,
        waypoints=objective.nodes(x[None])[0],
        trajectory=trajectory,
        spline=fit,
        time_scale=float(scale),
        metrics=metrics,
        breakdown=breakdown,
        optimiser=search,
        verification=verification.check,
    )


def plan(
    scene: Scene,
    robot: ck.Robot | None = None,
    progress: Callable[[FireflyProgress], None] | None = None,
    threads: int | None = None,
    optimizer: Optimizer | None = None,
) -> PlanResult:
    """Plan a collision-free, jerk-continuous trajectory for ``scene``.

    ``solve(build_problem(scene, robot, threads), progress, optimizer)``: see
    :func:`~planning.problem.build_problem` and :func:`solve`.

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
    that is timed. It plans the paper case with two fireflies for one iteration.
    """
    from planning.io.bundled import paper_scene

    started = time.perf_counter()
    with contextlib.suppress(NoSolutionError):  # a search this small may find nothing: the kernels ran
        plan(paper_scene(fireflies=2, iterations=1), robot, threads=1)
    return time.perf_counter() - started
