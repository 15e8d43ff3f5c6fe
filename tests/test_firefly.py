from __future__ import annotations

import numpy as np
import pytest

from planning.errors import PlanningError
from planning.search.firefly import FireflyProgress, _sweep, firefly_minimize
from planning.search.firefly_settings import FireflySettings
from planning.search.optimizer import STALL_TOLERANCE


def sphere(x: np.ndarray) -> np.ndarray:
    return np.asarray(np.sum(x**2, axis=1))


def rastrigin(x: np.ndarray) -> np.ndarray:
    return np.asarray(10 * x.shape[1] + np.sum(x**2 - 10 * np.cos(2 * np.pi * x), axis=1))


YANG = FireflySettings(fireflies=40, iterations=100, alpha=0.2, beta0=1.0, gamma=1.0, theta=0.97)


@pytest.mark.parametrize("seed", range(5))
def test_yang_settings_solve_the_9d_sphere(seed: int) -> None:
    result = firefly_minimize(sphere, -5 * np.ones(9), 5 * np.ones(9), YANG, seed)
    assert result.fitness < 0.05
    assert result.fitness == pytest.approx(float(sphere(result.x[None])[0]))


def test_beats_random_search_on_rastrigin_with_equal_budget() -> None:
    lower, upper = -5.12 * np.ones(5), 5.12 * np.ones(5)
    settings = FireflySettings(fireflies=25, iterations=40, alpha=0.5, beta0=1.0, gamma=1.0, theta=0.95)
    budget = settings.fireflies * (settings.iterations + 1)
    firefly, random = [], []
    for seed in range(10):
        firefly.append(firefly_minimize(rastrigin, lower, upper, settings, seed).fitness)
        rng = np.random.default_rng(seed)
        random.append(float(rastrigin(rng.uniform(lower, upper, (budget, 5))).min()))
    assert np.median(firefly) < 0.5 * np.median(random)


def test_same_seed_same_run_and_parameters_matter() -> None:
    bounds = (-5 * np.ones(4), 5 * np.ones(4))
    settings = FireflySettings(fireflies=10, iterations=10)
    a = firefly_minimize(rastrigin, *bounds, settings, 3)
    b = firefly_minimize(rastrigin, *bounds, settings, np.random.default_rng(3))
    np.testing.assert_array_equal(a.population, b.population)
    np.testing.assert_array_equal(a.best_history, b.best_history)
    for changed in (
        FireflySettings(fireflies=10, iterations=10, beta0=0.9),
        FireflySettings(fireflies=10, iterations=10, gamma=5.0),
    ):
        c = firefly_minimize(rastrigin, *bounds, changed, 3)
        assert not np.array_equal(a.population, c.population)


@pytest.mark.parametrize("mode", ["sweep", "sequential"])
def test_evaluation_counts_bounds_and_history(mode: str) -> None:
    lower, upper = np.array([-1.0, 0.0, 10.0]), np.array([1.0, 0.5, 20.0])
    seen: list[np.ndarray] = []

    def objective(x: np.ndarray) -> np.ndarray:
        seen.append(x.copy())
        return rastrigin((x - lower) / (upper - lower))

    settings = FireflySettings(fireflies=8, iterations=6, alpha=2.0, mode=mode)  # type: ignore[arg-type]
    progress: list[FireflyProgress] = []
    result = firefly_minimize(objective, lower, upper, settings, 0, progress.append)
    points = np.vstack(seen)
    assert len(points) == result.evaluations == result.evaluation_history[-1]
    if mode == "sweep":
        assert result.evaluations == 8 * 7 and len(seen) == 7  # one batch call per iteration
    assert np.all(points >= lower) and np.all(points <= upper)
    assert [p.iteration for p in progress] == list(range(7))
    assert np.all(np.diff(result.best_history) <= 0)
    assert result.fitness == result.best_history[-1] == min(float(objective(p[None])[0]) for p in points)


def test_sweep_keeps_the_brightest_in_place() -> None:
    calls: list[np.ndarray] = []

    def objective(x: np.ndarray) -> np.ndarray:
        calls.append(x.copy())
        return sphere(x)

    firefly_minimize(objective, -np.ones(3), np.ones(3), FireflySettings(fireflies=6, iterations=1), 1)
    initial, after = calls
    brightest = int(np.argmin(sphere(initial)))
    np.testing.assert_array_equal(after[brightest], initial[brightest])
    assert not np.array_equal(np.delete(after, brightest, 0), np.delete(initial, brightest, 0))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_compiled_sweep_matches_a_plain_loop(seed: int) -> None:
    # Yang's sweep written out pair by pair: attractors where the sweep found them, every
    # firefly moving in turn towards each brighter one, with the same kicks
    rng = np.random.default_rng(seed)
    n, d = 9, 4
    u, f = rng.random((n, d)), rng.random(n)
    f[3] = f[5]  # a tie: neither moves towards the other
    settings = FireflySettings(fireflies=n, beta0=0.8, gamma=2.0)
    kicks = np.random.default_rng(seed + 100).random((n, n, d))
    expected = u.copy()
    for j in range(n):
        for i in range(n):
            if f[j] < f[i]:
                step = u[j] - expected[i]
                expected[i] += 0.8 * np.exp(-2.0 * step @ step) * step + 0.3 * (kicks[j, i] - 0.5)
    expected = np.clip(expected, 0.0, 1.0)
    moved = _sweep(u.copy(), f, 0.3, settings, np.random.default_rng(seed + 100))
    np.testing.assert_allclose(moved, expected, rtol=0, atol=1e-14)
    np.testing.assert_array_equal(moved[np.argmin(f)], u[np.argmin(f)])  # the brightest stays


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_sequential_mode_matches_niapy(seed: int) -> None:
    niapy = pytest.importorskip("niapy")
    from niapy.algorithms.basic import FireflyAlgorithm
    from niapy.problems import Problem
    from niapy.task import Task

    lower, upper = -5.12 * np.ones(4), 5.12 * np.ones(4)

    class Unit(Problem):  # type: ignore[misc]
        def __init__(self) -> None:
            super().__init__(dimension=4, lower=0.0, upper=1.0)

        def _evaluate(self, u: np.ndarray) -> float:
            return float(rastrigin((lower + u * (upper - lower))[None])[0])

    assert niapy.__version__
    task = Task(problem=Unit(), max_iters=8)
    algorithm = FireflyAlgorithm(population_size=12, alpha=0.5, beta0=1.0, gamma=1.0, theta=0.97, seed=seed)
    x_theirs, f_theirs = algorithm.run(task)
    settings = FireflySettings(
        fireflies=12, iterations=8, alpha=0.5, beta0=1.0, gamma=1.0, theta=0.97, mode="sequential"
    )
    ours = firefly_minimize(rastrigin, lower, upper, settings, seed)
    assert ours.fitness == f_theirs
    assert ours.evaluations == task.evals
    np.testing.assert_array_equal(ours.x, lower + x_theirs * (upper - lower))


@pytest.mark.parametrize(
    ("kwargs", "pattern"),
    [
        ({"fireflies": 0}, r"fireflies = 0 must be an integer in \[2, 1000\]"),
        ({"fireflies": True}, r"fireflies = True must be an integer in \[2, 1000\]"),
        ({"fireflies": 10**9}, r"fireflies = 1000000000 must be an integer in \[2, 1000\]"),
        ({"iterations": -1}, r"iterations = -1 must be an integer in \[0, 10000\]"),
        ({"fireflies": 1000, "iterations": 5000}, r"fireflies x \(iterations \+ 1\) = 5001000 evaluations"),
        ({"alpha": float("nan")}, r"alpha = nan must be a number in \[0, 10\]"),
        ({"alpha": 1e300}, r"alpha = 1e\+300 must be a number in \[0, 10\]"),
        ({"theta": 1.5}, r"theta = 1.5 must be a number in \(0, 1\]"),
        ({"mode": "parallel"}, "mode = 'parallel'; allowed: 'sweep', 'sequential'"),
    ],
)
def test_bad_settings(kwargs: dict[str, object], pattern: str) -> None:
    with pytest.raises(PlanningError, match=pattern):
        FireflySettings(**kwargs)  # type: ignore[arg-type]


def test_bad_bounds_and_objective() -> None:
    with pytest.raises(PlanningError, match="upper > lower"):
        firefly_minimize(sphere, np.ones(2), np.ones(2))
    with pytest.raises(PlanningError, match=r"objective returned shape \(3, 1\)"):
        firefly_minimize(
            lambda x: x[:, :1], np.zeros(2), np.ones(2), FireflySettings(fireflies=3, iterations=1)
        )


def test_early_stop_after_stalled_iterations_is_a_prefix_of_the_full_run() -> None:
    bounds = (-5 * np.ones(3), 5 * np.ones(3))
    full = firefly_minimize(rastrigin, *bounds, FireflySettings(fireflies=10, iterations=200), 4)
    early = firefly_minimize(
        rastrigin, *bounds, FireflySettings(fireflies=10, iterations=200, stall_iterations=5), 4
    )
    stop = len(early.best_history)
    assert stop < len(full.best_history)  # it stopped early ...
    np.testing.assert_array_equal(early.best_history, full.best_history[:stop])  # ... on the same run
    assert early.evaluations == 10 * stop
    # the rule: the last 5 iterations improved the best by less than the tolerance of it
    last, before = early.best_history[-1], early.best_history[-6]
    assert last >= before - STALL_TOLERANCE * abs(before)
    again = firefly_minimize(
        rastrigin, *bounds, FireflySettings(fireflies=10, iterations=200, stall_iterations=5), 4
    )
    np.testing.assert_array_equal(again.population, early.population)


def test_no_early_stop_while_the_best_is_above_stall_below() -> None:
    bounds = (-5 * np.ones(3), 5 * np.ones(3))
    settings = FireflySettings(fireflies=10, iterations=60, stall_iterations=3)
    unreachable = firefly_minimize(lambda x: sphere(x) + 10.0, *bounds, settings, 1, stall_below=5.0)
    assert len(unreachable.best_history) == 61
    reached = firefly_minimize(lambda x: sphere(x) + 10.0, *bounds, settings, 1, stall_below=np.inf)
    assert len(reached.best_history) < 61
