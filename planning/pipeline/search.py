"""The search stage: an attempt's waypoints searched on its problem's objective.

By default the planner's own search, :class:`~planning.search.refined_firefly.RefinedFirefly`:
the firefly from the attempt's seeds (and a random population), then, with ``refine: cma``,
the CMA-ES refinement from its best within the rest of the evaluation budget,
``fireflies x (iterations + 1)``. A caller's :class:`~planning.search.optimizer.Optimizer`
runs instead on the same objective and budget. Every draw comes from
``numpy.random.default_rng(seed)``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from planning.pipeline.problem import Problem
from planning.pipeline.seeding import Attempt
from planning.search.firefly import FireflyProgress
from planning.search.optimizer import Optimizer, SearchResult
from planning.search.refined_firefly import RefinedFirefly


def planner_search(
    problem: Problem,
    attempt: Attempt | None = None,
    progress: Callable[[FireflyProgress], None] | None = None,
) -> RefinedFirefly:
    """The planner's search for ``problem``, from ``attempt``'s seeds (module docstring)."""
    settings, objective = problem.scene.planner, problem.objective
    return RefinedFirefly(
        firefly=settings.firefly,
        refinement=settings.tuning.refinement if settings.refine == "cma" else None,
        stall_generations=settings.refine_stall,
        seeds=None if attempt is None else attempt.seeds,
        feasible_below=objective.feasible_below,
        lower_bound=objective.lower_bound if settings.refine == "cma" else None,
        progress=progress,
        explore=settings.tuning.explore_feasible_seed or attempt is None or not attempt.feasible_seed,
        stop=problem.deadline.passed,
    )


def search(
    attempt: Attempt,
    progress: Callable[[FireflyProgress], None] | None = None,
    optimizer: Optimizer | None = None,
) -> SearchResult:
    """Search ``attempt``'s problem: the planner's search, or ``optimizer`` on the same budget.

    Args:
        attempt: the problem and where its search starts.
        progress: called after every firefly iteration (the planner's search only).
        optimizer: another optimiser; default: :func:`planner_search`.
    """
    problem = attempt.problem
    objective, settings = problem.objective, problem.scene.planner
    if optimizer is None:
        optimizer = planner_search(problem, attempt, progress)
    rng = np.random.default_rng(settings.seed)
    return optimizer(objective, objective.lower, objective.upper, settings.firefly.evaluations, rng)
