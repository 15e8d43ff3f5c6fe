"""The closest pair by bounds first: coal's answer over every pair, from fewer queries."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.collision.closest_pairs import closest_pairs
from tests.conftest import random_configurations


@pytest.fixture(scope="module")
def cluttered(robot: ck.Robot) -> ck.CollisionWorld:
    """The CPR among a crate, a pillar and a ball, so that many configurations pass within 5 cm."""
    return ck.CollisionWorld(
        robot,
        [
            ck.Obstacle.box(size=(0.3, 0.3, 0.3), xyz=(0.0, 0.6, 0.15), name="crate"),
            ck.Obstacle.cylinder(radius=0.05, length=0.8, xyz=(0.4, 0.2, 0.4), name="pillar"),
            ck.Obstacle.sphere(radius=0.1, xyz=(-0.3, 0.3, 0.5), name="ball"),
        ],
    )


def every_pair(world: ck.CollisionWorld, q: np.ndarray) -> np.ndarray:
    """``(N, P)`` coal's distance of every robot-obstacle pair, one query each."""
    return np.array([[pair.distance_m for pair in world.clearance(x).pairs] for x in q])


class CountingDistance:
    """``pin.computeDistance`` that counts its calls."""

    def __init__(self) -> None:
        self.calls, self._compute = 0, pin.computeDistance

    def __call__(self, *args: Any) -> Any:
        self.calls += 1
        return self._compute(*args)


@pytest.mark.parametrize("below_m", [0.0, 0.05, 0.15])
def test_the_closest_below_a_bound_is_coals_over_every_pair(
    robot: ck.Robot, cluttered: ck.CollisionWorld, rng: np.random.Generator, below_m: float
) -> None:
    q = random_configurations(robot, rng, 400)
    exact = every_pair(cluttered, q)
    smallest = exact.min(axis=1)
    distance, pair = cluttered.min_clearance_batch(q, below_m=below_m)
    near = smallest < below_m
    assert 0 < near.sum() < len(q) or below_m == 0.0
    # coal's GJK and EPA start from the pair's last answer: the order of queries moves results by ~1e-6
    np.testing.assert_allclose(distance[near], smallest[near], rtol=0.0, atol=1e-5)
    assert np.all(exact[near, pair[near]] <= smallest[near] + 1e-5)  # the pair named is at that distance
    assert np.all(np.isinf(distance[~near])) and np.all(pair[~near] == -1)


def test_exact_bounds_cost_one_query_and_useless_ones_every_pair(
    robot: ck.Robot, cluttered: ck.CollisionWorld, rng: np.random.Generator, monkeypatch: pytest.MonkeyPatch
) -> None:
    q = random_configurations(robot, rng, 60)
    exact = every_pair(cluttered, q)
    clear = exact.min(axis=1) > 0.01
    q, exact = q[clear], exact[clear]
    pairs = np.arange(exact.shape[1])
    model, geometry_model = robot.model, cluttered.geometry_model
    counting = CountingDistance()
    monkeypatch.setattr(pin, "computeDistance", counting)
    distance, closest = closest_pairs(
        model, model.createData(), geometry_model, geometry_model.createData(), q, exact - 1e-3, pairs
    )
    assert counting.calls == len(q)  # the closest pair's bound is the smallest, and the next is farther
    np.testing.assert_allclose(distance, exact.min(axis=1), atol=1e-5)
    np.testing.assert_array_equal(closest, exact.argmin(axis=1))
    counting.calls = 0
    useless = np.zeros_like(exact)  # a bound of 0 says nothing: every pair must be asked
    distance, _ = closest_pairs(
        model, model.createData(), geometry_model, geometry_model.createData(), q, useless, pairs
    )
    assert counting.calls == exact.size
    np.testing.assert_allclose(distance, exact.min(axis=1), atol=1e-5)


def test_a_non_positive_bound_never_hides_a_deeper_penetration(
    robot: ck.Robot, cluttered: ck.CollisionWorld, rng: np.random.Generator
) -> None:
    q = random_configurations(robot, rng, 400)
    exact = every_pair(cluttered, q)
    inside = (exact < 0).sum(axis=1) >= 2  # two or more pairs overlap
    assert inside.sum() >= 3
    q, exact = q[inside], exact[inside]
    # the overlapping pairs bounded in the wrong order: the shallowest looks closest
    bounds = np.where(exact < 0, -1.0 - exact, exact)
    distance, _ = closest_pairs(
        robot.model,
        robot.model.createData(),
        cluttered.geometry_model,
        cluttered.geometry_model.createData(),
        q,
        bounds,
        np.arange(exact.shape[1]),
    )
    np.testing.assert_allclose(distance, exact.min(axis=1), atol=1e-5)
