"""Local refinement of a search's best point: a CMA-ES started at it with a small step.

The firefly explores and finds the basin; near its best point its moves are too coarse to
descend (a sweep kicks every firefly by about ``alpha sqrt(n) / 2`` per iteration), and its
early stop ends the search there. A covariance matrix adaptation evolution strategy (Hansen
2016, "The CMA Evolution Strategy: A Tutorial", default parameters, :mod:`cma_rates`, and
its active covariance update unless the settings turn it off) learns the valley's
directions from a few generations and walks along them, also where the valley does not
follow the variables' axes (the tests: a rotated quadratic of condition number 1000, where
a search that adapts only its step length needs about that many times more evaluations).
What it gains on planning scenes and the paper objective: ``docs/tuning.md``.

Written here rather than taken from ``cma`` or ``cmaes``: both import ``scipy.stats``, a large
part of the time a plan may take in a new process; the method itself is the textbook's, in
normalised coordinates ``u in [0, 1]^d`` like the firefly. Samples outside the box are
clipped onto it and the clipped steps enter the update (repair), so every evaluated point
lies in the box.

The refinement ends when its best value has improved by less than a relative
:data:`~planning.search.optimizer.STALL_TOLERANCE` over ``stall_generations`` generations
in a row while within :attr:`RefinementSettings.near_bound` times the objective's lower
bound (when one is given), when its step has shrunk below
:attr:`RefinementSettings.min_sigma`, or when the next generation would exceed the
evaluation budget. The same generator state gives the same run.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from numpy.typing import ArrayLike, NDArray

from planning.errors import PlanningError
from planning.search.cma_rates import LearningRates, population_size
from planning.search.optimizer import BatchObjective, EarlyStop, History, SearchResult, evaluate_in_box
from planning.search.refinement_settings import STALL_GENERATIONS, RefinementSettings

FloatArray = NDArray[np.float64]


def cma_refine(
    objective: BatchObjective,
    lower: ArrayLike,
    upper: ArrayLike,
    start: ArrayLike,
    start_value: float,
    budget: int,
    rng: np.random.Generator,
    settings: RefinementSettings | None = None,
    *,
    stall_generations: int = STALL_GENERATIONS,
    lower_bound: float | None = None,
    stop: Callable[[], bool] | None = None,
) -> SearchResult:
    """Refine ``start`` (value ``start_value``) with a CMA-ES within ``budget`` evaluations.

    Args:
        objective: batch objective ``(S, d) -> (S,)``; every point passed lies in the box.
        lower: ``(d,)`` lower bounds.
        upper: ``(d,)`` upper bounds, each > the lower one.
        start: ``(d,)`` point of the box to start from (the mean of the first generation).
        start_value: its objective value (not evaluated again).
        budget: most evaluations; fewer than one generation: no refinement.
        rng: the generator of the samples.
        settings: step, covariance update and stopping rules (default:
            :class:`RefinementSettings`'s).
        stall_generations: generations in a row without a relative improvement of
            ``STALL_TOLERANCE`` that end the refinement; 0: run out the budget (or the step).
        lower_bound: about the least value the objective can take (e.g. a waypoint
            objective's ``lower_bound``); stalled generations count only while the best is
            within ``settings.near_bound`` times it. ``None``: always.
        stop: asked before every generation; ``True`` ends the refinement with its best so
            far (a time limit). ``None``: never.

    Returns:
        The best of ``start`` and every evaluated point; histories per generation (entry 0:
        the start). ``population`` and ``population_fitness`` hold the points that improved
        on the best, newest (best) first: a caller whose own check refuses the best (it
        went closest to a constraint) falls back along the way the refinement came.
    """
    lo = np.asarray(lower, dtype=float)
    span = np.asarray(upper, dtype=float) - lo
    x0 = np.asarray(start, dtype=float)
    if x0.shape != lo.shape or span.shape != lo.shape or not np.all(span > 0):
        raise PlanningError(
            f"start of shape {x0.shape} and bounds of shapes {lo.shape}, {span.shape}; "
            "expected (d,) each with upper > lower"
        )
    settings = settings or RefinementSettings()
    sigma, active = settings.sigma, settings.active
    if lower_bound is not None and not math.isfinite(lower_bound):
        raise PlanningError(f"lower_bound = {lower_bound!r} must be a finite number (or None)")
    near = math.inf if lower_bound is None else settings.near_bound * lower_bound
    d = lo.size
    lam = population_size(d)
    rates = LearningRates.of(d, active)
    weights, negative = rates.weights, rates.negative_weights
    mu = weights.size
    mu_eff, c_1, c_mu = rates.mu_eff, rates.c_1, rates.c_mu
    c_sigma = (mu_eff + 2) / (d + mu_eff + 5)
    d_sigma = 1 + 2 * max(0.0, math.sqrt((mu_eff - 1) / (d + 1)) - 1) + c_sigma
    c_c = (4 + mu_eff / d) / (d + 4 + 2 * mu_eff / d)
    chi_n = math.sqrt(d) * (1 - 1 / (4 * d) + 1 / (21 * d**2))

    mean = np.clip((x0 - lo) / span, 0.0, 1.0)
    cov = np.eye(d)
    basis, scales = np.eye(d), np.ones(d)  # cov = basis diag(scales^2) basis^T
    p_sigma, p_c = np.zeros(d), np.zeros(d)
    best_u, best_f = mean.copy(), float(start_value)
    improved: list[tuple[FloatArray, float]] = []
    history = History()
    history.record(best_f, best_f, 0)
    evaluations, generation = 0, 0
    early_stop = EarlyStop(stall_generations, best_f)
    while evaluations + lam <= budget and sigma >= settings.min_sigma and not (stop is not None and stop()):
        generation += 1
        steps = rng.standard_normal((lam, d)) @ (basis * scales).T
        population = np.clip(mean + sigma * steps, 0.0, 1.0)
        steps = (population - mean) / sigma  # the repaired steps enter the update
        values = evaluate_in_box(objective, lo, span, population)
        evaluations += lam
        order = np.argsort(values, kind="stable")
        if values[order[0]] < best_f:
            best_u, best_f = population[order[0]].copy(), float(values[order[0]])
            improved.append((best_u, best_f))
        selected = steps[order[:mu]]
        step = weights @ selected
        mean = mean + sigma * step
        whitened = basis @ ((basis.T @ step) / scales)  # cov^(-1/2) step
        p_sigma = (1 - c_sigma) * p_sigma + math.sqrt(c_sigma * (2 - c_sigma) * mu_eff) * whitened
        norm = float(np.linalg.norm(p_sigma))
        h_sigma = norm / math.sqrt(1 - (1 - c_sigma) ** (2 * generation)) < (1.4 + 2 / (d + 1)) * chi_n
        p_c = (1 - c_c) * p_c + h_sigma * math.sqrt(c_c * (2 - c_c) * mu_eff) * step
        cov = (
            (1 - c_1 - c_mu * (1 + negative.sum())) * cov
            + c_1 * (np.outer(p_c, p_c) + (not h_sigma) * c_c * (2 - c_c) * cov)
            + c_mu * (selected.T * weights) @ selected
        )
        if active:  # the worst steps, rescaled to the Mahalanobis norm sqrt(d), shrink the
            # covariance along them (a constraint's normal, where the worst land)
            worst = steps[order[mu:]]
            worst_norms = np.sum((worst @ basis / scales) ** 2, axis=1)
            cov = cov + c_mu * (worst.T * (negative * d / np.maximum(worst_norms, 1e-20))) @ worst
        sigma *= math.exp(min(1.0, (c_sigma / d_sigma) * (norm / chi_n - 1)))
        cov = (cov + cov.T) / 2
        eigenvalues, basis = np.linalg.eigh(cov)
        scales = np.sqrt(np.maximum(eigenvalues, 1e-20))
        history.record(best_f, float(np.mean(values)), evaluations)
        if early_stop.update(best_f, counts=best_f <= near):
            break
    newest_first = improved[::-1]
    population = np.array([u for u, _ in newest_first]).reshape(-1, d)
    return history.result(lo, span, best_u, best_f, population, np.array([f for _, f in newest_first]))


def refine_search(
    objective: BatchObjective,
    lower: ArrayLike,
    upper: ArrayLike,
    searched: SearchResult,
    budget: int,
    rng: np.random.Generator,
    settings: RefinementSettings | None = None,
    *,
    stall_generations: int = STALL_GENERATIONS,
    lower_bound: float | None = None,
    stop: Callable[[], bool] | None = None,
) -> SearchResult:
    """``searched`` (a global search's result) refined by :func:`cma_refine` from its best point.

    Returns one result for both phases: the refined best; ``budget`` bounds the refinement's
    evaluations, which add to ``searched``'s; the histories run on through the refinement's
    generations. The population is ``searched``'s with, ahead of it, some of the points that
    improved on its best: the newest and then those at least ``settings.fallback_spacing`` of
    the whole improvement apart, so that a caller whose check refuses the best (the
    refinement goes as close to the constraints as the objective lets it) falls back to
    distinct, less tight points before the global search's. ``settings``,
    ``stall_generations``, ``lower_bound`` and ``stop`` are :func:`cma_refine`'s.
    """
    settings = settings or RefinementSettings()
    refined = cma_refine(
        objective,
        lower,
        upper,
        searched.x,
        searched.fitness,
        budget,
        rng,
        settings,
        stall_generations=stall_generations,
        lower_bound=lower_bound,
        stop=stop,
    )
    if refined.evaluations == 0:
        return searched
    spacing = settings.fallback_spacing * (searched.fitness - refined.fitness)
    keep: list[int] = []
    for index, value in enumerate(refined.population_fitness):  # best first
        if not keep or value >= refined.population_fitness[keep[-1]] + spacing:
            keep.append(index)
    return SearchResult(
        x=refined.x,
        fitness=refined.fitness,
        evaluations=searched.evaluations + refined.evaluations,
        best_history=np.concatenate([searched.best_history, refined.best_history[1:]]),
        mean_history=np.concatenate([searched.mean_history, refined.mean_history[1:]]),
        evaluation_history=np.concatenate(
            [searched.evaluation_history, searched.evaluations + refined.evaluation_history[1:]]
        ),
        population=np.vstack([refined.population[keep], searched.population]),
        population_fitness=np.concatenate([refined.population_fitness[keep], searched.population_fitness]),
    )
