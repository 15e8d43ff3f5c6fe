"""RRT-Connect's paths as seeds of the waypoint search: drawn, cut to waypoints, ranked.

Steps 2 and 3 of :mod:`planning.pipeline.seeding` that concern the sampling planner's path:
:func:`sampled_path` draws one clear of the fitness's clearance, :func:`followable_path`
draws up to ``path_attempts`` until the spline through one's waypoints is feasible, and
:func:`fewest_waypoints` gives a path the waypoints the spline needs to follow it.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.pipeline.problem import Problem, with_planner
from planning.pipeline.settings import MAX_WAYPOINTS, PlannerSettings
from planning.search.edges import ScreenedValidity, Validity
from planning.search.rrt_connect import Relaxation, RrtPath, rrt_connect
from planning.search.rrt_settings import RrtSettings
from planning.search.waypoints import placements_along

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

DEADLINE_SAMPLES = 100_000
"""Most samples of a draw when the plan has a time limit (``time_limit_s``): the limit, the
time its user gave the plan, ends a hard draw rather than the seeding's ``max_samples``."""


def draw_samples(problem: Problem) -> int:
    """Samples RRT-Connect's draw may take: ``max_samples``, or :data:`DEADLINE_SAMPLES` with a time limit.

    With a time limit the limit ends a hard draw first, so that a path that needs more
    samples than the seeding's ``max_samples`` is not given up while the user's time lasts.
    """
    max_samples = problem.scene.planner.tuning.seeding.max_samples
    return max_samples if problem.deadline.limit_s is None else max(max_samples, DEADLINE_SAMPLES)


class PathSeed(NamedTuple):
    """A path's seed.

    Attributes:
        fitness: its fitness on ``problem``'s objective.
        problem: the problem it seeds (with the waypoints it has).
        x: its decision vector.
    """

    fitness: float
    problem: Problem
    x: FloatArray


FinerProblem = Callable[[], Problem]
"""``problem`` with a finer certified step (:func:`~planning.pipeline.seeding.finer_problem`),
built when first asked: most draws end before the trees would keep its clearance."""


def sampled_path(
    problem: Problem,
    rng: np.random.Generator,
    settings: RrtSettings | None = None,
    finer: FinerProblem | None = None,
    max_samples: int | None = None,
) -> RrtPath | None:
    """RRT-Connect's path in the moving joints of ``problem``, clear of the fitness's clearance.

    With ``finer`` (``problem`` with a finer certified step, so a smaller clearance), the
    trees go on keeping its clearance after the seeding's ``finer_after`` samples, or from
    the start where an end is too close for ``problem``'s; the path is then ``relaxed``.
    ``finer`` is called only then.
    ``max_samples``: the draw's budget, in place of ``settings``' (``None``: theirs; the
    default settings take :func:`draw_samples`). The trees start from the problem's
    :attr:`~planning.pipeline.problem.Problem.grown` trees where an earlier draw between its
    ends left them, and are left there when no path is found.
    """
    robot, moving = problem.robot, problem.moving
    tuning = problem.scene.planner.tuning.seeding
    if settings is None:
        settings = RrtSettings(
            max_samples=draw_samples(problem),
            resolution_m=edge_resolution_m(problem),
            explore_resolution_m=tuning.max_resolution_m,
            local_share=tuning.local_share,
            local_spread=tuning.local_spread,
            joint_shortcuts=tuning.joint_shortcuts,
        )
    if max_samples is not None:
        settings = dataclasses.replace(settings, max_samples=max_samples)
    limits = robot.limits
    relaxation = None if finer is None else Relaxation(clearance_validity(problem, finer), tuning.finer_after)
    return rrt_connect(
        clearance_validity(problem),
        problem.q_start[moving],
        problem.q_goal[moving],
        limits.lower[moving],
        limits.upper[moving],
        ck.path_weights(robot)[moving],
        rng,
        settings,
        problem.deadline.passed,
        relaxation,
        problem.grown,
        speeds=limits.velocity[moving],
    )


def clearance_validity(problem: Problem, kept: FinerProblem | None = None) -> Validity:
    """Whether configurations of ``problem``'s moving joints keep the fitness's clearance.

    From obstacles and between the robot's own pairs, and, with a gravity limit, can be held
    still. ``kept``: the problem whose clearance is kept (a finer one, built at the first
    check; default: ``problem``'s own). For a robot with pairs of its own, a
    :class:`~planning.search.edges.ScreenedValidity` whose screen is the obstacles' clearance
    alone: RRT-Connect's trees grow on that, most of their edges thrown away, and the path
    they find is held under the whole check (``docs/tuning.md``).
    """

    def valid(q: FloatArray) -> BoolArray:
        objective = (problem if kept is None else kept()).objective
        required_m, required_self_m = objective.required_m, objective.required_self_m
        configurations = problem.configurations(q)
        free = problem.world.keeps_clearance(configurations, required_m, required_self_m, ordered=True)
        if problem.gravity is not None and free.any():  # and can be held still
            free[free] = problem.gravity.holds(configurations[free])
        return free

    def obstacles_kept(q: FloatArray) -> BoolArray:
        required_m = (problem if kept is None else kept()).objective.required_m
        return ~problem.world.margin_violated(problem.configurations(q), required_m, ordered=True)

    if not problem.world.self_collision:
        return valid
    return ScreenedValidity(valid, obstacles_kept)


def edge_resolution_m(problem: Problem) -> float:
    """How far apart a path's edges are checked [m]: at most as far as the clearance required."""
    tuning = problem.scene.planner.tuning.seeding
    return min(tuning.max_resolution_m, max(0.01, problem.objective.required_m))


def path_seed(problem: Problem, path: FloatArray, count: int, weights: FloatArray) -> PathSeed:
    """The seed of ``path`` with ``count`` waypoints along it: the best of the tuning's placements.

    The placements (:func:`~planning.search.waypoints.placements_along`) are evaluated in
    one batch; the first of the best fitness is kept.
    """
    counted = with_planner(problem, waypoints=count)
    shares = problem.scene.planner.tuning.seeding.placements
    offered = placements_along(path, count, weights, shares).reshape(len(shares), -1)
    fitness = counted.objective(offered)
    best = int(np.argmin(fitness))
    return PathSeed(float(fitness[best]), counted, offered[best])


def followable_path(
    problem: Problem, weights: FloatArray, finer: FinerProblem | None = None
) -> tuple[FloatArray | None, PathSeed | None]:
    """RRT-Connect's path whose waypoints seed ``problem`` best, and its seed.

    Step 2 of :mod:`planning.pipeline.seeding`: up to ``path_attempts`` paths, all drawn
    from the stream ``default_rng([seed, 1])``, another only while those drawn took fewer
    than ``redraw_samples`` samples in all, and given what remains of them: a redraw that
    needs more gives up (a path is in hand; one that takes thousands of samples costs more
    than a better seed saves). The first whose seed is feasible, else the one of the best
    fitness; ``None`` when RRT-Connect finds none in its first draw (a further draw is not
    tried: a failed one has used up its samples). A path found keeping only ``finer``'s
    clearance (:func:`sampled_path`) seeds ``finer``.
    """
    settings = problem.scene.planner
    tuning = settings.tuning.seeding
    rng = np.random.default_rng([settings.seed, 1])
    best: tuple[FloatArray, PathSeed] | None = None
    samples = 0
    for _ in range(tuning.path_attempts):
        budget = None if best is None else tuning.redraw_samples - samples
        found = sampled_path(problem, rng, finer=finer, max_samples=budget)
        if found is None:
            break
        samples += found.samples
        kept = finer() if finer is not None and found.relaxed else problem
        seeded = path_seed(kept, found.path, corner_waypoints(settings, found.path), weights)
        if best is None or seeded.fitness < best[1].fitness:
            best = (found.path, seeded)
        if kept.objective.feasible(seeded.fitness) or samples >= tuning.redraw_samples:
            break
    return (None, None) if best is None else best


def corner_waypoints(settings: PlannerSettings, path: FloatArray) -> int:
    """The waypoints of ``path``'s seed: one per interior corner, between the planner's and the tuning's most.

    At least ``settings.waypoints``; more, one per corner, up to
    :attr:`~planning.pipeline.tuning.SeedingTuning.corner_waypoints`.
    """
    corners = len(path) - 2
    return max(settings.waypoints, min(corners, settings.tuning.seeding.corner_waypoints))


def fewest_waypoints(problem: Problem, path: FloatArray, weights: FloatArray) -> PathSeed:
    """The seed of ``path`` with the fewest waypoints beyond ``problem``'s that keeps the clearance.

    Two or more beyond them, the path's corners at least, then two more at a time up to
    ``more_waypoints`` more (and :data:`~planning.pipeline.settings.MAX_WAYPOINTS`); if none
    keeps it, the count whose seed ranks best.
    """
    settings = problem.scene.planner
    first = min(max(settings.waypoints + 2, len(path) - 2), MAX_WAYPOINTS)
    last = min(first + settings.tuning.seeding.more_waypoints, MAX_WAYPOINTS)
    best: PathSeed | None = None
    for count in range(first, last + 1, 2):
        seeded = path_seed(problem, path, count, weights)
        if best is None or seeded.fitness < best.fitness:
            best = seeded
        if seeded.problem.objective.feasible(seeded.fitness):  # the fewest waypoints that follow
            break
    assert best is not None  # the range is never empty
    return best
