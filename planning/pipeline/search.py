"""The search stage: an attempt's waypoints searched on its problem's objective.

By default the planner's own search, :class:`~planning.search.refined_firefly.RefinedFirefly`:
the firefly from the attempt's seeds (and a random population), then, with ``refine: cma``,
the CMA-ES refinement from its best within the rest of the evaluation budget,
``fireflies x (iterations + 1)``. A caller's :class:`~planning.search.optimizer.Optimizer`
runs instead on the same objective and budget. Every draw comes from
``numpy.random.default_rng(seed)``.

The planner's search asks the plan's deadline itself (:mod:`planning.pipeline.deadline`), as a
search holding a feasible candidate once its objective has seen one
(:attr:`~planning.pipeline.deadline.Deadline.feasible_at_s`: the hulls' share of a limit ends
only a search that found none). A
caller's optimiser knows nothing of it, so it gets the objective watched: once the deadline
has passed, the watched objective's next call raises :class:`TimeUp` through the optimiser
(after its first batch, so that something was evaluated), and the search returns the best
candidate the objective saw. :class:`TimeUp` derives from ``BaseException``, as
``asyncio.CancelledError`` does: an optimiser's ``except Exception`` does not swallow it.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from planning.pipeline.problem import Problem
from planning.pipeline.seeding import Attempt
from planning.pipeline.tuning import SearchTuning
from planning.search.firefly import FireflyProgress
from planning.search.optimizer import BatchObjective, Optimizer, SearchResult
from planning.search.refined_firefly import RefinedFirefly

FloatArray = NDArray[np.float64]


class TimeUp(BaseException):
    """Raised by a watched objective once the plan's deadline has passed (module docstring)."""


class WatchedObjective:
    """``objective`` keeping the best candidate it evaluated; past ``passed()`` it raises :class:`TimeUp`.

    Args:
        objective: the batch objective watched.
        passed: whether time is up (the plan's :meth:`~planning.pipeline.deadline.Deadline.passed`).
    """

    def __init__(self, objective: BatchObjective, passed: Callable[[], bool]) -> None:
        self.objective, self.passed = objective, passed
        self.best_x: FloatArray | None = None
        self.best_value = math.inf
        self.evaluations = 0

    def __call__(self, x: FloatArray) -> FloatArray:
        """``(S,)`` values of ``x`` ``(S, d)``; :class:`TimeUp` once time is up (never on the first call)."""
        if self.evaluations and self.passed():
            raise TimeUp
        values = np.asarray(self.objective(x), dtype=float)
        self.evaluations += len(values)
        if len(values) and (self.best_x is None or float(np.min(values)) < self.best_value):
            k = int(np.argmin(values))
            self.best_x, self.best_value = np.array(x[k], dtype=float), float(values[k])
        return values

    def result(self) -> SearchResult:
        """The best candidate seen, as a search's result (one entry per history); after a call."""
        assert self.best_x is not None  # TimeUp comes only after a call
        return SearchResult.of_point(self.best_x, self.best_value, self.evaluations)


def planner_search(
    problem: Problem,
    attempt: Attempt | None = None,
    progress: Callable[[FireflyProgress], None] | None = None,
    stop: Callable[[], bool] | None = None,
) -> RefinedFirefly:
    """The planner's search for ``problem``, from ``attempt``'s seeds (module docstring).

    ``stop``: asked between its iterations and generations (default: the problem's deadline).
    """
    settings, objective = problem.scene.planner, problem.objective
    return RefinedFirefly(
        firefly=settings.firefly,
        refinement=settings.tuning.refinement if settings.refine == "cma" else None,
        stall_generations=settings.refine_stall,
        seeds=None if attempt is None else attempt.seeds,
        feasible_below=objective.feasible_below,
        lower_bound=objective.lower_bound if settings.refine == "cma" else None,
        progress=progress,
        explore=explores(attempt, settings.tuning),
        stop=stop or problem.deadline.passed,
    )


def explores(attempt: Attempt | None, tuning: SearchTuning) -> bool:
    """Whether the firefly explores before the refinement, or the refinement starts from the seeds at once.

    At once from a feasible seed, or from one that follows the sampling planner's path
    (unless ``explore_feasible_seed`` and ``explore_path_seed`` ask otherwise); the firefly
    explores from the straight line alone, or without seeds.
    """
    if attempt is None or attempt.seeds is None:
        return True
    if attempt.feasible_seed:
        return tuning.explore_feasible_seed
    if attempt.path is not None:
        return tuning.explore_path_seed
    return True


def search(
    attempt: Attempt,
    progress: Callable[[FireflyProgress], None] | None = None,
    optimizer: Optimizer | None = None,
) -> SearchResult:
    """Search ``attempt``'s problem: the planner's search, or ``optimizer`` on the same budget.

    Args:
        attempt: the problem and where its search starts.
        progress: called after every firefly iteration (the planner's search only).
        optimizer: another optimiser; default: :func:`planner_search`. It is stopped at the
            plan's deadline through its objective (module docstring).
    """
    problem = attempt.problem
    objective, settings = problem.objective, problem.scene.planner
    rng = np.random.default_rng(settings.seed)
    budget = settings.firefly.evaluations
    if optimizer is None:  # stopped by the deadline of a search with or without a feasible best
        seen = WatchedObjective(objective, lambda: False)

        def stop() -> bool:
            return problem.deadline.passed(feasible=seen.best_value <= objective.feasible_below)

        return planner_search(problem, attempt, progress, stop)(
            seen, objective.lower, objective.upper, budget, rng
        )
    watched = WatchedObjective(objective, problem.deadline.passed)
    try:
        return optimizer(watched, objective.lower, objective.upper, budget, rng)
    except TimeUp:
        return watched.result()
