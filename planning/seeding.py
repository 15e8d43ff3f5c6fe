"""Where the waypoint search starts: the straight line, or a sampling planner's path around what blocks it.

The firefly refines well but explores by chance: a passage under a beam or through a window
is a small part of its space, rarely met by a random population. So, with the planner's
``seeding: paths`` (the default):

1. the straight line from start to goal (its waypoints evenly on it) is a seed: with the
   duration free it is the fastest path when it is clear, and a good start when it is
   nearly clear;
2. if the spline through it violates the margin, RRT-Connect
   (:mod:`planning.search.rrt_connect`) looks for a path in the moving joints, clear of
   the clearance the fitness requires (margin plus verification step), and its waypoints
   (:func:`~planning.search.rrt_connect.waypoints_along`) are the second seed. A path is
   clear, but the spline through its few waypoints cuts its corners and may not be: then
   RRT-Connect draws another path, up to :data:`PATH_ATTEMPTS` in all, and the first whose
   seed is feasible (else the one whose seed ranks best) is taken. Each draw may find
   another way around the obstacles, and a feasible seed spares the search with more
   waypoints that an infeasible one leads to;
3. if a search with the scene's waypoints fails, the planner asks for more
   (``more_waypoints``): as many as the spline needs to follow the path: at least two
   more and the path's corners, then two more at a time (up to :data:`MORE_WAYPOINTS`
   more, and :data:`~planning.scene.MAX_WAYPOINTS`) until the spline through them keeps
   the clearance; the fewest that do, else the count whose seed ranks best. (Fewer
   waypoints first: a spline through many is slower to run and harder to search.)

The seeds and :data:`SEED_SPREAD`-sized moves around them make up :data:`SEED_SHARE` of the
initial population. The sampling planner and the moves draw from their own streams,
``default_rng([seed, 1])`` and ``[seed, 2]``: the firefly's draws are the same with or
without them, and the same seed gives the same seeds.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.problem import Problem, with_planner
from planning.scene import MAX_WAYPOINTS
from planning.search.rrt_connect import RrtPath, RrtSettings, rrt_connect, waypoints_along

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

SEED_SHARE = 0.6
"""Share of the population that starts at or around the seeds (the rest is random)."""
SEED_SPREAD = 0.01
"""Standard deviation of the moves around a seed, as a share of each variable's range: the
firefly then refines around the seeds from its first iteration (a lone seed among random
fireflies stays the best, unmoved, until the others come near). Backed by
``scripts/study_parameters.py``."""
MAX_RESOLUTION_M = 0.04
"""Largest spacing of the sampling planner's edge checks [m]: the checks cost most of its time,
and a path that clips an obstacle between two checks is only a seed (the fitness and the
certified check judge what is executed). It is never more than the clearance required (a
thin obstacle with no margin is checked every centimetre)."""
PATH_ATTEMPTS = 3
"""Most RRT-Connect paths drawn while the spline through a path's waypoints violates the
clearance. ``scripts/study_parameters.py`` on 110 generated scenes (generator seeds 0, 1, 2;
12 narrow passages): one path, as before, gives 1.8-5.6 % longer trajectories than 3
attempts (geometric mean per scene set; 10 % longer or more on a tenth of seed 2's scenes,
where the first path went the long way round), 2 attempts 0-1.8 % longer, 5 attempts 1 %
shorter to 1.8 % longer; the median planning time is the same for all (a feasible seed
spares the search with more waypoints that an infeasible one leads to)."""
MORE_WAYPOINTS = 6
"""How many waypoints beyond the path's corners the seeding may add, two at a time, until the
spline through them keeps the clearance (a tight passage needs the spline held close to the
path)."""

PathSeed = tuple[float, Problem, FloatArray]
"""A path's seed: its fitness, the problem it seeds (the waypoints it has) and the decision vector."""


@dataclass(frozen=True)
class Seeds:
    """The search's starting points.

    Attributes:
        problem: the problem to search (the one given, or it with more waypoints).
        candidates: ``(k, d)`` decision vectors of the problem's objective.
        path: the sampling planner's path in the moving joints, or ``None`` when the
            straight line was clear or no path was found [joint units].
        straight_line_clear: the straight line's candidate is feasible.
        time_s: wall time of the seeding [s].
    """

    problem: Problem
    candidates: FloatArray
    path: FloatArray | None
    straight_line_clear: bool
    time_s: float


def sampled_path(
    problem: Problem, rng: np.random.Generator, settings: RrtSettings | None = None
) -> RrtPath | None:
    """RRT-Connect's path in the moving joints of ``problem``, clear of the fitness's clearance."""
    robot, moving, objective = problem.robot, problem.moving, problem.objective
    held = problem.q_start

    def valid(q: FloatArray) -> BoolArray:
        full = np.repeat(held[None], len(q), axis=0)
        full[:, moving] = q
        return ~problem.world.margin_violated(full, objective.required_m)

    if settings is None:  # edges checked at most as far apart as the clearance required, 1-4 cm
        settings = RrtSettings(resolution_m=min(MAX_RESOLUTION_M, max(0.01, objective.required_m)))
    limits = robot.limits
    return rrt_connect(
        valid,
        problem.q_start[moving],
        problem.q_goal[moving],
        limits.lower[moving],
        limits.upper[moving],
        ck.motion_radii(robot)[moving],
        rng,
        settings,
    )


def seed_search(problem: Problem, more_waypoints: bool = False, path: FloatArray | None = None) -> Seeds:
    """The seeds of ``problem``'s search (module docstring).

    Args:
        problem: the problem; searched with its own waypoints unless ``more_waypoints``.
        more_waypoints: a search with the problem's waypoints failed: give the search two or
            more waypoints beyond them, as many as the spline needs to follow the path.
        path: the path an earlier call found (saves finding it again).
    """
    started = time.perf_counter()
    straight = problem.objective.straight_line()
    clear = bool(problem.objective.breakdown(straight[None]).feasible[0])
    weights = ck.motion_radii(problem.robot)[problem.moving]
    seeded: PathSeed | None = None
    if path is None and not clear:
        path, seeded = _followable_path(problem, weights)
    if path is None:
        return Seeds(problem, _around(problem, straight[None]), None, clear, time.perf_counter() - started)
    if more_waypoints:
        seeded = _fewest_waypoints(problem, path, weights)
    elif seeded is None:
        seeded = _path_seed(problem, path, problem.scene.planner.waypoints, weights)
    _, problem, along = seeded
    candidates = np.array([problem.objective.straight_line(), along])
    return Seeds(problem, _around(problem, candidates), path, clear, time.perf_counter() - started)


def _path_seed(problem: Problem, path: FloatArray, count: int, weights: FloatArray) -> PathSeed:
    """The seed of ``path`` with ``count`` waypoints along it: its fitness, problem and decision vector."""
    counted = with_planner(problem, waypoints=count)
    along = waypoints_along(path, count, weights).ravel()
    return float(counted.objective(along[None])[0]), counted, along


def _followable_path(problem: Problem, weights: FloatArray) -> tuple[FloatArray | None, PathSeed | None]:
    """RRT-Connect's path whose waypoints seed ``problem`` best (module docstring, step 2), and its seed.

    Up to :data:`PATH_ATTEMPTS` paths, all drawn from the stream ``default_rng([seed, 1])``;
    the first whose seed is feasible, else the one of the best fitness; ``None`` when
    RRT-Connect finds none (a further draw is not tried: a failed one has used up its samples).
    """
    rng = np.random.default_rng([problem.scene.planner.seed, 1])
    best: tuple[FloatArray, PathSeed] | None = None
    for _ in range(PATH_ATTEMPTS):
        found = sampled_path(problem, rng)
        if found is None:
            break
        seeded = _path_seed(problem, found.path, problem.scene.planner.waypoints, weights)
        if best is None or seeded[0] < best[1][0]:
            best = (found.path, seeded)
        if seeded[0] <= problem.objective.t_max:
            break
    return (None, None) if best is None else best


def _fewest_waypoints(problem: Problem, path: FloatArray, weights: FloatArray) -> PathSeed:
    """The seed of ``path`` with the fewest waypoints beyond ``problem``'s that keeps the clearance.

    Two or more beyond them, the path's corners at least, then two more at a time up to
    :data:`MORE_WAYPOINTS` more (and :data:`~planning.scene.MAX_WAYPOINTS`); if none keeps
    it, the count whose seed ranks best.
    """
    first = min(max(problem.scene.planner.waypoints + 2, len(path) - 2), MAX_WAYPOINTS)
    best: PathSeed | None = None
    for count in range(first, min(first + MORE_WAYPOINTS, MAX_WAYPOINTS) + 1, 2):
        seeded = _path_seed(problem, path, count, weights)
        if best is None or seeded[0] < best[0]:
            best = seeded
        if seeded[0] <= seeded[1].objective.t_max:  # feasible: the fewest waypoints that follow
            break
    assert best is not None  # the range is never empty
    return best


def _around(problem: Problem, seeds: FloatArray) -> FloatArray:
    """``seeds``, then copies of them moved at random: :data:`SEED_SHARE` of the population."""
    objective, settings = problem.objective, problem.scene.planner
    count = max(len(seeds), int(SEED_SHARE * settings.firefly.fireflies))
    rng = np.random.default_rng([settings.seed, 2])
    picks = seeds[np.arange(count - len(seeds)) % len(seeds)]
    span = objective.upper - objective.lower
    moved = picks + SEED_SPREAD * span * rng.standard_normal(picks.shape)
    return np.concatenate([seeds, np.clip(moved, objective.lower, objective.upper)])
