from __future__ import annotations

import numpy as np
import pytest

from planning.errors import PlanningError
from planning.search.firefly_settings import FireflySettings
from planning.search.optimizer import evaluated_points
from planning.search.refined_firefly import RefinedFirefly
from planning.search.refinement_settings import RefinementSettings

D = 6
CENTRE = np.linspace(0.2, 0.4, D)
LOWER, UPPER = -np.ones(D), np.ones(D)
FIREFLY = FireflySettings(fireflies=12, iterations=40, alpha=0.2, stall_iterations=3)
BUDGET = FIREFLY.evaluations
SEEDS = np.array([CENTRE + 0.3, CENTRE - 0.5, np.zeros(D)])


def bowl(x: np.ndarray) -> np.ndarray:
    """An axis-aligned quadratic, least value 0 at CENTRE."""
    return np.asarray(np.sum(np.linspace(1, 4, D) * (x - CENTRE) ** 2, axis=1))


def test_evaluated_points_are_a_result_best_first() -> None:
    result = evaluated_points(bowl, LOWER, UPPER, SEEDS)
    values = bowl(SEEDS)
    assert result.evaluations == len(SEEDS)
    assert result.fitness == values.min()
    np.testing.assert_allclose(result.x, SEEDS[np.argmin(values)])
    np.testing.assert_allclose(result.population_fitness, np.sort(values))
    np.testing.assert_allclose(bowl(result.population), result.population_fitness)
    assert result.best_history.tolist() == [values.min()]
    assert result.evaluation_history.tolist() == [len(SEEDS)]


@pytest.mark.parametrize(
    "points", [np.zeros((0, D)), np.zeros((2, D + 1)), np.full((1, D), 1.5), np.zeros(D)]
)
def test_evaluated_points_refuse_what_is_not_a_batch_of_the_box(points: np.ndarray) -> None:
    with pytest.raises(PlanningError, match=r"points of shape .* must be k >= 1 points of the box"):
        evaluated_points(bowl, LOWER, UPPER, points)


def search(explore: bool, feasible_below: float) -> RefinedFirefly:
    return RefinedFirefly(firefly=FIREFLY, seeds=SEEDS, feasible_below=feasible_below, explore=explore)


def test_a_feasible_seed_is_refined_without_the_firefly() -> None:
    direct = search(False, np.inf)(bowl, LOWER, UPPER, BUDGET, np.random.default_rng(3))
    explored = search(True, np.inf)(bowl, LOWER, UPPER, BUDGET, np.random.default_rng(3))
    # the refinement's history starts at the seeds' best, after their evaluations only
    assert direct.best_history[0] == bowl(SEEDS).min()
    assert direct.evaluation_history[0] == len(SEEDS)
    assert explored.evaluation_history[0] == FIREFLY.fireflies
    assert direct.fitness < 0.1 * bowl(SEEDS).min()
    assert direct.evaluations <= BUDGET
    # the seeds stay in the population as fallbacks behind the refinement's points
    np.testing.assert_allclose(direct.population_fitness[-len(SEEDS) :], np.sort(bowl(SEEDS)))


def test_without_explore_the_best_seed_is_refined_feasible_or_not() -> None:
    """Which seeds are refined at once is the caller's rule (the planner's: ``search.explores``)."""
    below_every_seed = 0.5 * bowl(SEEDS).min()
    direct = search(False, below_every_seed)(bowl, LOWER, UPPER, BUDGET, np.random.default_rng(3))
    explored = search(True, below_every_seed)(bowl, LOWER, UPPER, BUDGET, np.random.default_rng(3))
    assert direct.evaluation_history[0] == len(SEEDS) and direct.best_history[0] == bowl(SEEDS).min()
    assert explored.evaluation_history[0] == FIREFLY.fireflies
    assert direct.fitness < below_every_seed  # the refinement's steps go below it


@pytest.mark.parametrize(("feasible_below", "feasible"), [(np.inf, True), (0.0, False)])
def test_an_infeasible_best_starts_the_refinement_with_the_larger_step(
    feasible_below: float, feasible: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    import planning.search.refined_firefly as module
    from planning.search.refinement import refine_search as refine

    steps: list[float] = []

    def recording(*args: object, **kwargs: object) -> object:
        steps.append(args[6].sigma)  # type: ignore[attr-defined]  # the settings, positional
        return refine(*args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(module, "refine_search", recording)
    settings = RefinementSettings(sigma=0.01, infeasible_sigma=0.05)
    optimiser = RefinedFirefly(
        firefly=FIREFLY, refinement=settings, seeds=SEEDS, feasible_below=feasible_below, explore=False
    )
    optimiser(bowl, LOWER, UPPER, BUDGET, np.random.default_rng(3))
    assert steps == [0.01 if feasible else 0.05]


def test_refinement_steps_are_validated() -> None:
    with pytest.raises(PlanningError, match=r"infeasible_sigma = 0\.0 must be a number in \(0, 1\]"):
        RefinementSettings(infeasible_sigma=0.0)
    with pytest.raises(PlanningError, match=r"min_sigma = 0\.02 must be a number in \(0, 0\.01\]"):
        RefinementSettings(sigma=0.05, infeasible_sigma=0.01, min_sigma=0.02)
