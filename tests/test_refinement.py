from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from planning.errors import PlanningError
from planning.search.cma_rates import LearningRates, population_size
from planning.search.firefly import firefly_minimize
from planning.search.firefly_settings import FireflySettings
from planning.search.optimizer import STALL_TOLERANCE, SearchResult
from planning.search.refinement import cma_refine, refine_search
from planning.search.refinement_settings import STALL_GENERATIONS
from planning.search.refinement_settings import RefinementSettings as R

FALLBACK_SPACING = R().fallback_spacing
NEAR_BOUND = R().near_bound

D = 10
ROTATION = np.linalg.qr(np.random.default_rng(1).standard_normal((D, D)))[0]
HESSIAN = ROTATION @ np.diag(10 ** np.linspace(0, 3, D)) @ ROTATION.T  # condition number 1000
CENTRE = np.linspace(0.2, 0.4, D)


def ellipsoid(x: np.ndarray) -> np.ndarray:
    """A rotated ill-conditioned quadratic: minimum 0 at CENTRE."""
    step = x - CENTRE
    return np.asarray(np.einsum("ij,jk,ik->i", step, HESSIAN, step))


def mild(x: np.ndarray) -> np.ndarray:
    """An axis-aligned quadratic of condition number 10: minimum 0 at CENTRE."""
    return np.asarray(np.sum(np.linspace(1, 10, D) * (x - CENTRE) ** 2, axis=1))


def rosenbrock(x: np.ndarray) -> np.ndarray:
    return np.asarray(np.sum(100 * (x[:, 1:] - x[:, :-1] ** 2) ** 2 + (1 - x[:, :-1]) ** 2, axis=1))


def start_of(objective: Callable[[np.ndarray], np.ndarray], x0: np.ndarray) -> tuple[np.ndarray, float]:
    return x0, float(objective(x0[None])[0])


def test_population_size_is_cma_es_default() -> None:
    assert [population_size(d) for d in (1, 2, 5, 10, 15, 100)] == [4, 6, 8, 10, 12, 17]


@pytest.mark.parametrize("dimension", [2, 5, 10, 15, 20, 40])
def test_learning_rates_are_the_tutorials(dimension: int) -> None:
    rates = LearningRates.of(dimension)
    lam = population_size(dimension)
    mu = lam // 2
    assert rates.weights.shape == (mu,) and rates.negative_weights.shape == (lam - mu,)
    assert rates.weights.sum() == pytest.approx(1.0)
    assert np.all(np.diff(rates.weights) < 0) and np.all(rates.weights > 0)
    assert rates.mu_eff == pytest.approx(rates.weights.sum() ** 2 / np.sum(rates.weights**2))
    assert np.all(rates.negative_weights <= 0) and np.all(np.diff(rates.negative_weights) < 0)
    # the worse half's mass keeps the covariance positive definite: the decay left after
    # the positive updates covers the negative one at its largest (every step at norm sqrt(d))
    mass = -rates.negative_weights.sum()
    assert rates.c_mu * mass * dimension <= 1 - rates.c_1 - rates.c_mu + 1e-12
    assert mass <= 1 + rates.c_1 / rates.c_mu + 1e-12
    classic = LearningRates.of(dimension, active=False)
    np.testing.assert_array_equal(classic.negative_weights, 0.0)
    np.testing.assert_array_equal(classic.weights, rates.weights)


def band(x: np.ndarray) -> np.ndarray:
    """Minimise ``-(x0 + x1)`` within ``|x0 - x1| <= 0.01``, a thin band along the diagonal;
    outside it, a penalty above every feasible value."""
    off = np.abs(x[:, 0] - x[:, 1])
    return np.asarray(np.where(off <= 0.01, -(x[:, 0] + x[:, 1]), 10 + off))


def test_active_update_walks_along_a_constraint() -> None:
    # the worse half lands across the band: unlearning those steps narrows the search to it
    x0 = np.array([0.1, 0.1, 0.5, 0.5, 0.5, 0.5])
    f0 = float(band(x0[None])[0])
    gains = {}
    for active in (True, False):
        runs = [
            cma_refine(
                band,
                np.zeros(6),
                np.ones(6),
                x0,
                f0,
                300,
                np.random.default_rng(s),
                R(0.03, active),
                stall_generations=0,
            )
            for s in range(20)
        ]
        assert all(-2.0 <= run.fitness <= f0 for run in runs)
        gains[active] = f0 - float(np.median([run.fitness for run in runs]))
    assert gains[True] > 2 * gains[False] > 0


def test_learns_a_rotated_ill_conditioned_quadratic() -> None:
    # a step-size-only search needs ~condition-number times more evaluations on it
    x0, f0 = start_of(ellipsoid, np.full(D, 0.7))
    rng = np.random.default_rng(0)
    result = cma_refine(ellipsoid, np.zeros(D), np.ones(D), x0, f0, 4000, rng, R(0.1), stall_generations=0)
    assert result.fitness < 1e-6 * f0
    np.testing.assert_allclose(result.x, CENTRE, atol=1e-3)
    assert result.evaluations <= 4000


def test_solves_rosenbrock_in_a_box() -> None:
    x0, f0 = start_of(rosenbrock, np.zeros(5))
    rng = np.random.default_rng(3)
    result = cma_refine(
        rosenbrock, -2 * np.ones(5), 2 * np.ones(5), x0, f0, 20_000, rng, R(0.1), stall_generations=0
    )
    assert result.fitness < 1e-6
    np.testing.assert_allclose(result.x, np.ones(5), atol=1e-2)


def test_optimum_on_the_boundary_is_reached_from_inside() -> None:
    # minimum of the quadratic outside the box: the refinement ends on the nearest face
    def shifted(x: np.ndarray) -> np.ndarray:
        return np.asarray(np.sum((x - 1.5) ** 2, axis=1))

    x0, f0 = start_of(shifted, np.full(3, 0.2))
    seen: list[np.ndarray] = []

    def recording(x: np.ndarray) -> np.ndarray:
        seen.append(x.copy())
        return shifted(x)

    result = cma_refine(
        recording,
        np.zeros(3),
        np.ones(3),
        x0,
        f0,
        3000,
        np.random.default_rng(0),
        R(0.2),
        stall_generations=0,
    )
    assert np.all(np.concatenate(seen) >= 0.0) and np.all(np.concatenate(seen) <= 1.0)
    np.testing.assert_allclose(result.x, np.ones(3), atol=1e-4)


def test_budget_history_and_never_worse_than_the_start() -> None:
    x0, f0 = start_of(rosenbrock, np.full(4, 0.5))
    result = cma_refine(rosenbrock, -np.ones(4), np.ones(4), x0, f0, 100, np.random.default_rng(2))
    lam = population_size(4)
    assert result.evaluations <= 100 and result.evaluations % lam == 0
    assert result.fitness <= f0
    assert result.best_history[0] == f0
    assert np.all(np.diff(result.best_history) <= 0)
    assert np.array_equal(np.diff(result.evaluation_history), np.full(len(result.best_history) - 1, lam))
    assert result.fitness == pytest.approx(float(rosenbrock(result.x[None])[0]))
    # the improving points, best first, each one the best so far when it was found
    assert result.population_fitness[0] == result.fitness
    assert np.all(np.diff(result.population_fitness) > 0)
    np.testing.assert_allclose(rosenbrock(result.population), result.population_fitness)


def test_stall_rule_ends_on_a_flat_objective() -> None:
    flat = lambda x: np.ones(len(x))  # noqa: E731
    result = cma_refine(flat, np.zeros(3), np.ones(3), np.full(3, 0.5), 1.0, 10_000, np.random.default_rng(0))
    assert result.evaluations == STALL_GENERATIONS * population_size(3)
    assert len(result.population) == 0 and result.fitness == 1.0


def test_stall_counts_relative_improvements() -> None:
    # each generation improves by less than STALL_TOLERANCE of the best: a stall
    calls = iter(range(1, 10_000))
    creeping = lambda x: np.full(len(x), 1.0 - 0.1 * STALL_TOLERANCE * next(calls))  # noqa: E731
    result = cma_refine(
        creeping, np.zeros(2), np.ones(2), np.full(2, 0.5), 1.0, 10_000, np.random.default_rng(0)
    )
    assert result.evaluations == STALL_GENERATIONS * population_size(2)


def test_too_small_a_budget_evaluates_nothing() -> None:
    result = cma_refine(
        rosenbrock, np.zeros(4), np.ones(4), np.full(4, 0.5), 3.0, 7, np.random.default_rng(0)
    )
    assert result.evaluations == 0 and result.fitness == 3.0
    np.testing.assert_array_equal(result.x, np.full(4, 0.5))


def test_same_generator_state_same_run() -> None:
    x0, f0 = start_of(rosenbrock, np.full(6, 0.3))
    runs = [
        cma_refine(
            rosenbrock,
            -np.ones(6),
            np.ones(6),
            x0,
            f0,
            600,
            np.random.default_rng(7),
            R(0.05),
            stall_generations=0,
        )
        for _ in range(2)
    ]
    np.testing.assert_array_equal(runs[0].x, runs[1].x)
    np.testing.assert_array_equal(runs[0].best_history, runs[1].best_history)


@pytest.mark.parametrize(
    ("start", "sigma", "message"),
    [(np.zeros(3), 0.1, "shape"), (np.zeros(4), 0.0, "sigma = 0.0"), (np.zeros(4), 1.5, "sigma = 1.5")],
)
def test_bad_arguments_name_the_value(start: np.ndarray, sigma: float, message: str) -> None:
    with pytest.raises(PlanningError, match=message):
        cma_refine(rosenbrock, np.zeros(4), np.ones(4), start, 1.0, 100, np.random.default_rng(0), R(sigma))


def test_refine_search_continues_a_firefly_run() -> None:
    lower, upper = -np.ones(D), np.ones(D)
    settings = FireflySettings(fireflies=20, iterations=30, alpha=0.2, stall_iterations=3)
    rng = np.random.default_rng(4)
    searched = firefly_minimize(mild, lower, upper, settings, rng)
    budget = settings.fireflies * (settings.iterations + 1) - searched.evaluations
    result = refine_search(mild, lower, upper, searched, budget, rng, stall_generations=0)
    assert result.fitness < 0.1 * searched.fitness
    assert result.evaluations <= settings.fireflies * (settings.iterations + 1)
    # the histories run on from the firefly's
    n = len(searched.best_history)
    np.testing.assert_array_equal(result.best_history[:n], searched.best_history)
    np.testing.assert_array_equal(result.evaluation_history[:n], searched.evaluation_history)
    assert result.evaluation_history[-1] == result.evaluations
    assert np.all(np.diff(result.best_history) <= 0)
    # fallbacks ahead of the firefly's population: distinct steps of the descent, best first
    kept = len(result.population) - len(searched.population)
    assert kept >= 2
    np.testing.assert_array_equal(result.population[kept:], searched.population)
    fallbacks = result.population_fitness[:kept]
    assert fallbacks[0] == result.fitness
    assert np.all(np.diff(fallbacks) >= FALLBACK_SPACING * (searched.fitness - result.fitness))
    assert fallbacks[-1] < searched.fitness


def test_refine_search_without_budget_returns_the_search() -> None:
    settings = FireflySettings(fireflies=10, iterations=5)
    searched = firefly_minimize(ellipsoid, -np.ones(D), np.ones(D), settings, 0)
    assert (
        refine_search(ellipsoid, -np.ones(D), np.ones(D), searched, 5, np.random.default_rng(0)) is searched
    )


def offset_bowl(x: np.ndarray) -> np.ndarray:
    """A quadratic bowl whose least value is 1 (at CENTRE's first four coordinates)."""
    return 1.0 + np.asarray(np.sum((x - CENTRE[:4]) ** 2, axis=1))


def test_stalls_count_only_near_the_lower_bound() -> None:
    x0, f0 = start_of(offset_bowl, np.full(4, 0.9))
    lam = population_size(4)

    def run(lower_bound: float | None) -> SearchResult:
        rng = np.random.default_rng(3)
        return cma_refine(
            offset_bowl, np.zeros(4), np.ones(4), x0, f0, 3000, rng, R(0.05), stall_generations=2,
            lower_bound=lower_bound,
        )  # fmt: skip

    always, near, far = run(None), run(1.0), run(0.5)
    # the bound 1 is the least value: the stop comes once within NEAR_BOUND of it, as before
    assert near.fitness <= NEAR_BOUND * 1.0
    assert near.evaluations < 3000 - lam
    # counting only from there never stops sooner than counting every stall
    assert near.evaluations >= always.evaluations
    # a bound the objective cannot come near: no stall counts, the run ends at the budget or
    # when its step collapses, and finds the minimum
    assert far.evaluations > near.evaluations
    assert far.fitness == pytest.approx(1.0, abs=1e-6)


def test_a_lower_bound_must_be_finite() -> None:
    x0, f0 = start_of(offset_bowl, np.full(4, 0.9))
    with pytest.raises(PlanningError, match="lower_bound = nan must be a finite number"):
        cma_refine(
            offset_bowl, np.zeros(4), np.ones(4), x0, f0, 100, np.random.default_rng(0), lower_bound=np.nan
        )
