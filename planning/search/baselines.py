"""Baseline optimisers behind the firefly's batch interface, for benchmarks.

Every optimiser is an :class:`~planning.search.optimizer.Optimizer`: a batch objective, box bounds, an
evaluation budget and a ``numpy.random.Generator``; it returns a
:class:`~planning.search.optimizer.SearchResult` (best point, history, final population), so the
planner can use any of them (``plan(scene, optimizer=...)``) on the same objective and
budget. They all search normalised coordinates, like the firefly.

- :func:`firefly`: ours (sweep mode, the scene's parameters).
- :func:`particle_swarm` and :func:`harmony_search`: the algorithms Severin & Rossmann
  compared with the firefly (written here: a global-best PSO with constriction
  coefficients; harmony search improvising a batch of harmonies from the memory per step).
- :func:`differential_evolution`: ``scipy.optimize.differential_evolution``, vectorised.
- :func:`cma_es`: ``cma`` (optional peer), warm-started at the best of a first random batch.
- :func:`niapy_firefly`: NiaPy's ``FireflyAlgorithm`` (optional peer), one candidate per call.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from planning.search.firefly import firefly_minimize
from planning.search.firefly_settings import FireflySettings
from planning.search.optimizer import BatchObjective, History, Optimizer, SearchResult

FloatArray = NDArray[np.float64]


class _Tracker:
    """Wraps an objective in unit coordinates: counts, keeps the best, records history."""

    def __init__(self, objective: BatchObjective, lower: FloatArray, upper: FloatArray, budget: int) -> None:
        self.objective, self.lower, self.span, self.budget = objective, lower, upper - lower, budget
        self.evaluations = 0
        self.best_u: FloatArray = np.full(lower.size, 0.5)
        self.best_f = np.inf
        self.history = History()

    @property
    def left(self) -> int:
        return self.budget - self.evaluations

    def __call__(self, u: FloatArray) -> FloatArray:
        u = np.clip(np.atleast_2d(u), 0.0, 1.0)[: max(self.left, 0)]
        if len(u) == 0:
            return np.empty(0)
        f = np.asarray(self.objective(self.lower + u * self.span), dtype=float)
        self.evaluations += len(u)
        k = int(np.argmin(f))
        if f[k] < self.best_f:
            self.best_u, self.best_f = u[k].copy(), float(f[k])
        self.history.record(self.best_f, float(np.mean(f)), self.evaluations)
        return f

    def result(self, population: FloatArray, fitness: FloatArray) -> SearchResult:
        return self.history.result(
            self.lower, self.span, self.best_u, self.best_f, np.atleast_2d(population), fitness
        )


def firefly(settings: FireflySettings) -> Optimizer:
    """Our firefly algorithm with ``settings``; its iterations follow from the budget."""

    def run(
        objective: BatchObjective, lower: FloatArray, upper: FloatArray, budget: int, rng: np.random.Generator
    ) -> SearchResult:
        iterations = max(budget // settings.fireflies - 1, 0)
        adjusted = FireflySettings(**{**settings.__dict__, "iterations": iterations})
        return firefly_minimize(objective, lower, upper, adjusted, rng)

    return run


def particle_swarm(
    particles: int = 50, inertia: float = 0.7298, c1: float = 1.4962, c2: float = 1.4962
) -> Optimizer:
    """Global-best particle swarm (Clerc's constriction coefficients), one batch per iteration."""

    def run(
        objective: BatchObjective, lower: FloatArray, upper: FloatArray, budget: int, rng: np.random.Generator
    ) -> SearchResult:
        track = _Tracker(objective, lower, upper, budget)
        d = lower.size
        x = rng.random((particles, d))
        v = (rng.random((particles, d)) - 0.5) * 0.2
        f = track(x)
        best_x, best_f = x.copy(), f.copy()
        while track.left > 0:
            g = best_x[int(np.argmin(best_f))]
            r1, r2 = rng.random((particles, d)), rng.random((particles, d))
            v = np.clip(inertia * v + c1 * r1 * (best_x - x) + c2 * r2 * (g - x), -0.25, 0.25)
            x = np.clip(x + v, 0.0, 1.0)
            f_new = track(x)
            x, v = x[: len(f_new)], v[: len(f_new)]
            better = f_new < best_f[: len(f_new)]
            best_x[: len(f_new)][better], best_f[: len(f_new)][better] = x[better], f_new[better]
        return track.result(best_x, best_f)

    return run


def harmony_search(
    memory: int = 30, hmcr: float = 0.9, par: float = 0.3, bandwidth: float = 0.05, batch: int = 50
) -> Optimizer:
    """Harmony search (Geem 2001), improvising ``batch`` harmonies per step.

    Each new harmony then replaces the worst one in the memory if it beats it.
    """

    def run(
        objective: BatchObjective, lower: FloatArray, upper: FloatArray, budget: int, rng: np.random.Generator
    ) -> SearchResult:
        track = _Tracker(objective, lower, upper, budget)
        d = lower.size
        harmonies = rng.random((memory, d))
        values = track(harmonies)
        while track.left > 0:
            picks = harmonies[rng.integers(0, memory, (batch, d)), np.arange(d)]
            from_memory = rng.random((batch, d)) < hmcr
            adjust = from_memory & (rng.random((batch, d)) < par)
            new = np.where(from_memory, picks, rng.random((batch, d)))
            new = np.clip(new + adjust * bandwidth * (2 * rng.random((batch, d)) - 1), 0.0, 1.0)
            new_values = track(new)
            for candidate, value in zip(new[: len(new_values)], new_values, strict=True):
                worst = int(np.argmax(values))
                if value < values[worst]:
                    harmonies[worst], values[worst] = candidate, value
        return track.result(harmonies, values)

    return run


def differential_evolution(population: int = 50) -> Optimizer:
    """``scipy.optimize.differential_evolution`` (best1bin, deferred updates, vectorised)."""

    def run(
        objective: BatchObjective, lower: FloatArray, upper: FloatArray, budget: int, rng: np.random.Generator
    ) -> SearchResult:
        from scipy.optimize import differential_evolution as scipy_de

        track = _Tracker(objective, lower, upper, budget)
        d = lower.size
        popsize = max(int(np.ceil(population / d)), 1)
        size = popsize * d
        result = scipy_de(
            lambda u: (
                np.concatenate(
                    [track(u.T), np.full(u.shape[1] - min(u.shape[1], max(track.left, 0)), np.inf)]
                )
                if track.left < u.shape[1]
                else track(u.T)
            ),
            [(0.0, 1.0)] * d,
            popsize=popsize,
            maxiter=max(budget // size - 1, 0),
            vectorized=True,
            updating="deferred",
            polish=False,
            tol=0.0,
            rng=rng,
            init="latinhypercube",
        )
        population_u = getattr(result, "population", result.x[None])
        energies = getattr(result, "population_energies", np.array([result.fun]))
        return track.result(population_u, energies)

    return run


def cma_es(population: int = 50, sigma0: float = 0.25) -> Optimizer:
    """CMA-ES (``cma``), warm-started at the best of a first batch of random candidates."""

    def run(
        objective: BatchObjective, lower: FloatArray, upper: FloatArray, budget: int, rng: np.random.Generator
    ) -> SearchResult:
        import cma

        track = _Tracker(objective, lower, upper, budget)
        first = rng.random((population, lower.size))
        values = track(first)
        options: dict[str, Any] = {
            "bounds": [0.0, 1.0],
            "popsize": population,
            "seed": int(rng.integers(1, 2**31 - 1)),
            "verbose": -9,
            "maxfevals": budget,
        }
        strategy = cma.CMAEvolutionStrategy(first[int(np.argmin(values))], sigma0, options)
        asked, told = first, values
        while track.left > 0 and not strategy.stop():
            asked = np.array(strategy.ask())
            told = track(asked)
            if len(told) < len(asked):
                break
            strategy.tell(list(asked), list(told))
        return track.result(asked[: len(told)], told)

    return run


def niapy_firefly(settings: FireflySettings) -> Optimizer:
    """NiaPy's ``FireflyAlgorithm`` with the same parameters, stopped at the budget."""

    def run(
        objective: BatchObjective, lower: FloatArray, upper: FloatArray, budget: int, rng: np.random.Generator
    ) -> SearchResult:
        from niapy.algorithms.basic import FireflyAlgorithm
        from niapy.problems import Problem
        from niapy.task import Task

        track = _Tracker(objective, lower, upper, budget)

        class Unit(Problem):  # type: ignore[misc]
            def __init__(self) -> None:
                super().__init__(dimension=lower.size, lower=0.0, upper=1.0)

            def _evaluate(self, u: FloatArray) -> float:
                values = track(u[None])
                return float(values[0]) if len(values) else float("inf")

        algorithm = FireflyAlgorithm(
            population_size=settings.fireflies,
            alpha=settings.alpha,
            beta0=settings.beta0,
            gamma=settings.gamma,
            theta=settings.theta,
            seed=int(rng.integers(0, 2**31 - 1)),
        )
        algorithm.run(Task(problem=Unit(), max_evals=budget))
        return track.result(track.best_u[None], np.array([track.best_f]))

    return run
