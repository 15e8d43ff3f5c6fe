"""Where the waypoint search starts, and what it tries next when a search fails.

The firefly refines well but explores by chance: a passage under a beam or through a window
is a small part of its space, rarely met by a random population. So, with the planner's
``seeding: paths`` (the default, :class:`PathSeeding`):

1. the straight line from start to goal (its waypoints evenly on it) is a seed: with the
   duration free it is the fastest path when it is clear, and a good start when it is
   nearly clear;
2. if the spline through it violates the margin, RRT-Connect
   (:mod:`planning.search.rrt_connect`, drawn by :mod:`planning.pipeline.path_seeds`)
   looks for a path in the moving joints, clear of
   the clearance the fitness requires (margin plus verification step), and its waypoints
   are the second seed: one per corner of the path, at least the planner's ``waypoints``
   and at most ``corner_waypoints`` (:func:`~planning.pipeline.path_seeds.corner_waypoints`),
   the best of the ``placements`` along it, from its corners kept to evenly spaced
   (:func:`~planning.search.waypoints.placements_along`). A path is
   clear, but the spline through its few waypoints cuts its corners and may not be: then
   RRT-Connect draws another path, up to ``path_attempts`` in all while the paths so far
   took fewer than ``redraw_samples`` samples (a redraw gets what remains of them), and
   the first whose seed is feasible (else the one whose seed ranks best) is taken;
3. if a search with the scene's waypoints fails, the next attempt (:meth:`PathSeeding.after`)
   asks for more waypoints when no candidate was feasible (as many as the spline needs to
   follow the path: at least two more and the path's corners, then two more at a time, up
   to ``more_waypoints`` more and :data:`~planning.pipeline.settings.MAX_WAYPOINTS`, until the
   spline through them keeps the clearance), or for twice the fitness samples when feasible
   candidates failed the certified check (a violation between two samples escaped the
   fitness); ``retries`` times at most. Where RRT-Connect found no path, they do not ask it
   again: its draws are seeded and its clearance the same, so it would fail alike; and
   where no candidate was feasible without a path, there is none to add waypoints along:
   the next attempt would be the same search from the same seeds and draws, so there is
   none.

The clearance required is the margin plus the certified check's step (``verify_step_m``;
between the robot's own pairs the self margin plus its finer ``self_verify_step_m``): what
moves between two checks is counted against the margin. A passage narrower than that has
no path at that step, so the first attempt's RRT-Connect trees go on keeping only the
clearance of a finer step after ``finer_after`` samples (at once for a start or goal that
close, a grasp): ``finer_step`` of the step (1 mm of the default 5 mm; half an end's
clearance beyond its margin where less, :func:`finer_step_m`). What the trees grew holds at
the finer clearance too, so no sample is drawn again; a path found so is searched, and
certified, with the finer step.

The seeds and ``spread``-sized moves around them make up ``share`` of the initial
population (:class:`~planning.pipeline.tuning.SeedingTuning`); when a seed is feasible or
follows RRT-Connect's path, the search refines the best one without the firefly
(:func:`planning.pipeline.search.explores`). The sampling planner
and the moves draw from their own streams, ``default_rng([seed, 1])`` and ``[seed, 2]``:
the firefly's draws are the same with or without them. ``seeding: none`` (the paper,
:class:`NoSeeding`) searches once, from a random population.
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

import cpr_kin as ck
from planning.pipeline.path_seeds import (
    FinerProblem,
    PathSeed,
    corner_waypoints,
    draw_samples,
    fewest_waypoints,
    followable_path,
    path_seed,
)
from planning.pipeline.problem import Problem, finer_step_m, with_planner
from planning.pipeline.settings import MAX_FITNESS_SAMPLES
from planning.search.optimizer import SearchResult

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Seeds:
    """The search's starting points.

    Attributes:
        problem: the problem to search (the one given, or it with more waypoints).
        candidates: ``(k, d)`` decision vectors of the problem's objective.
        path: the sampling planner's path in the moving joints, or ``None`` when the
            straight line was clear or no path was found [joint units].
        straight_line_clear: the straight line's candidate is feasible.
        feasible: a seed is feasible, the straight line's or the path's.
        time_s: wall time of the seeding [s].
        no_path: RRT-Connect was asked for a path and found none.
    """

    problem: Problem
    candidates: FloatArray
    path: FloatArray | None
    straight_line_clear: bool
    feasible: bool
    time_s: float
    no_path: bool = False


@dataclass(frozen=True)
class Attempt:
    """One search of a plan: the problem searched and where the search starts.

    Attributes:
        problem: the problem to search.
        seeds: ``(k, d)`` starting points, or ``None`` (a random population).
        path: the sampling planner's path the seeds follow, reused by the next attempt.
        number: 0 for the first attempt, then 1, 2, ...
        tried: what the seeding tried and did not find, for a message (empty: nothing).
        feasible_seed: a seed is feasible (:func:`planning.pipeline.search.explores`).
        no_path: RRT-Connect found no path for this plan: the next attempts do not ask again.
    """

    problem: Problem
    seeds: FloatArray | None = None
    path: FloatArray | None = None
    number: int = 0
    tried: str = ""
    feasible_seed: bool = False
    no_path: bool = False


class Seeding(Protocol):
    """How a plan's attempts begin and follow one another (module docstring)."""

    def first(self, problem: Problem) -> Attempt:
        """The first attempt."""
        ...

    def after(self, attempt: Attempt, searched: SearchResult) -> Attempt | None:
        """The attempt after ``attempt``, whose search ``searched`` gave no verified trajectory."""
        ...


class NoSeeding:
    """One search from a random population (the paper's; also a caller's own optimiser)."""

    def first(self, problem: Problem) -> Attempt:  # noqa: D102 - the protocol's
        return Attempt(problem)

    def after(self, attempt: Attempt, searched: SearchResult) -> Attempt | None:  # noqa: D102
        return None


class PathSeeding:
    """The straight line and a sampling planner's path as seeds, escalated on failure (module docstring)."""

    def first(self, problem: Problem) -> Attempt:  # noqa: D102 - the protocol's
        seeds = seed_search(problem, finer=True)
        tried = ""
        if seeds.no_path and not problem.deadline.passed():  # else the time limit cut it short
            tuning = problem.scene.planner.tuning.seeding
            tried = f"no RRT-Connect path keeps {problem.objective.required_m:.4g} m clear"
            finer = finer_problem(problem)
            samples = draw_samples(problem)
            if finer is not None and tuning.finer_after < samples:
                tried += f" (nor {finer.objective.required_m:.4g} m after {tuning.finer_after})"
            tried += f" in {samples} samples"
            if problem.gravity is not None:
                tried += " through configurations the motors can hold still"
        return Attempt(seeds.problem, seeds.candidates, seeds.path, 0, tried, seeds.feasible, seeds.no_path)

    def after(self, attempt: Attempt, searched: SearchResult) -> Attempt | None:  # noqa: D102
        problem = attempt.problem
        if attempt.number >= problem.scene.planner.tuning.retries:
            return None
        widen = not problem.objective.feasible(searched.fitness)  # nothing feasible: more waypoints
        if widen and attempt.path is None:  # no path to follow with more: the same search again
            return None
        if not widen:  # feasible ones failed the certified check: check twice as many samples
            samples = problem.scene.planner.fitness_samples
            problem = with_planner(problem, fitness_samples=min(2 * samples, MAX_FITNESS_SAMPLES))
        seeds = seed_search(problem, widen, attempt.path, sample=not attempt.no_path)
        number, tried, no_path = attempt.number + 1, attempt.tried, attempt.no_path or seeds.no_path
        return Attempt(seeds.problem, seeds.candidates, seeds.path, number, tried, seeds.feasible, no_path)


SEEDINGS: dict[str, Seeding] = {"paths": PathSeeding(), "none": NoSeeding()}
"""The seeding rules by the scene file's name (``planner.seeding``)."""


def seed_search(
    problem: Problem,
    more_waypoints: bool = False,
    path: FloatArray | None = None,
    sample: bool = True,
    finer: bool = False,
) -> Seeds:
    """The seeds of ``problem``'s search (module docstring).

    Args:
        problem: the problem; searched with its own waypoints unless ``more_waypoints``.
        more_waypoints: a search with the problem's waypoints failed: give the search two or
            more waypoints beyond them, as many as the spline needs to follow the path.
        path: the path an earlier call found (saves finding it again).
        sample: ask RRT-Connect for a path when none is given and the straight line is not
            clear (``False``: an earlier call found none).
        finer: RRT-Connect's trees go on keeping the clearance of :func:`finer_problem`
            after ``finer_after`` samples, and a path found so seeds that problem.
    """
    started = time.perf_counter()
    straight = problem.objective.straight_line()
    clear = bool(problem.objective.breakdown(straight[None]).feasible[0])
    weights = ck.path_weights(problem.robot)[problem.moving]
    seeded: PathSeed | None = None
    asked = path is None and not clear and sample
    if asked:
        path, seeded = followable_path(problem, weights, lazy_finer_problem(problem) if finer else None)
    if path is None:
        elapsed = time.perf_counter() - started
        return Seeds(problem, _around(problem, straight[None]), None, clear, clear, elapsed, asked)
    if more_waypoints:
        seeded = fewest_waypoints(problem, path, weights)
    elif seeded is None:
        seeded = path_seed(problem, path, corner_waypoints(problem.scene.planner, path), weights)
    problem = seeded.problem
    candidates = np.array([problem.objective.straight_line(), seeded.x])
    feasible = clear or bool(problem.objective.feasible(seeded.fitness))
    return Seeds(problem, _around(problem, candidates), path, clear, feasible, time.perf_counter() - started)


def finer_problem(problem: Problem) -> Problem | None:
    """``problem`` with the finer certified step (:func:`finer_step_m`); ``None``: its own is as fine."""
    build = lazy_finer_problem(problem)
    return None if build is None else build()


def lazy_finer_problem(problem: Problem) -> FinerProblem | None:
    """:func:`finer_problem` as a function that builds it on its first call and keeps it.

    ``None`` where there is no finer step. Building a problem costs more than most
    RRT-Connect draws that could need it (about a millisecond on the CPR), and most end
    before the trees would keep its clearance.
    """
    step_m = finer_step_m(problem)
    if step_m >= problem.scene.planner.verify_step_m:
        return None
    return functools.cache(lambda: with_planner(problem, verify_step_m=step_m))


def _around(problem: Problem, seeds: FloatArray) -> FloatArray:
    """``seeds``, then copies of them moved at random: ``share`` of the population."""
    objective, settings = problem.objective, problem.scene.planner
    tuning = settings.tuning.seeding
    count = max(len(seeds), int(tuning.share * settings.firefly.fireflies))
    rng = np.random.default_rng([settings.seed, 2])
    picks = seeds[np.arange(count - len(seeds)) % len(seeds)]
    span = objective.upper - objective.lower
    moved = picks + tuning.spread * span * rng.standard_normal(picks.shape)
    return np.concatenate([seeds, np.clip(moved, objective.lower, objective.upper)])
