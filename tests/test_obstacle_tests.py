"""coal's margin test of the pairs the bounds leave: those alone, on the meshes where they decide."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.bounds.pair_bounds import PairBounds
from cpr_kin.collision.obstacle_tests import MAX_MARGINS, ObstacleTests
from cpr_kin.shapes.exact_pairs import ExactPairs

from .conftest import random_configurations
from .test_collision import random_obstacle
from .test_exact_pairs import UR5

TOLERANCE_M = 2e-6
"""coal's distance and its collision test may disagree this close to a margin [m]."""


def pair_distances(world: ck.CollisionWorld, q: np.ndarray) -> np.ndarray:
    """``(N, P)`` coal's distance of every pair [m] (the oracle)."""
    return np.array([[pair.distance_m for pair in world.clearance(x).pairs] for x in q])


@pytest.fixture(scope="module")
def cluttered(robot: ck.Robot) -> ck.CollisionWorld:
    rng = np.random.default_rng(41)
    obstacles = [random_obstacle(shape, rng) for shape in ("box", "sphere", "cylinder", "capsule") * 2]
    return ck.CollisionWorld(robot, [dataclasses.replace(o, name=f"o{k}") for k, o in enumerate(obstacles)])


def test_a_configuration_is_violated_where_a_pair_given_is_closer_than_the_margin(
    cluttered: ck.CollisionWorld,
) -> None:
    world = cluttered
    q = random_configurations(world.robot, np.random.default_rng(3), 300)
    distances = pair_distances(world, q)
    tests = ObstacleTests(world.robot.model, world.geometry_model)
    pairs = np.arange(distances.shape[1])
    rng = np.random.default_rng(4)
    for margin_m in (0.0, 0.03, 0.1):
        close: np.ndarray = distances < margin_m
        given: np.ndarray = rng.random(distances.shape) < 0.5  # coal tests these and no other
        decided = np.abs(distances - margin_m) > TOLERANCE_M
        for uncertain in (np.ones_like(close), given):
            violated = tests.violated(q, uncertain, pairs, margin_m)
            expected = (close & uncertain).any(axis=1)
            sure = (decided | ~uncertain).all(axis=1)
            np.testing.assert_array_equal(violated[sure], expected[sure])
        assert ((close & ~given).any(axis=1) & ~(close & given).any(axis=1)).any()  # a pair not given
        assert not tests.violated(q, np.zeros_like(close), pairs, margin_m).any()
    # the bounds' uncertain pairs give coal's answer over every pair
    every = [(g.index, k) for g in world.robot.geometries for k in range(len(world.obstacles))]
    assert len(every) == len(pairs)  # the world checks each geometry against each obstacle, in this order
    bounds = PairBounds(world.robot.model, world.robot.collision_model, world.obstacles, every)
    flagged = bounds.pairs_below(q, 0.05 + TOLERANCE_M)
    np.testing.assert_array_equal(
        tests.violated(q, flagged, pairs, 0.05), tests.violated(q, np.ones_like(flagged), pairs, 0.05)
    )
    assert flagged.mean() < 0.5  # and they are a few of them


def test_ordered_stops_at_the_first_violated(cluttered: ck.CollisionWorld) -> None:
    world = cluttered
    robot = world.robot
    tests = ObstacleTests(robot.model, world.geometry_model)
    rng = np.random.default_rng(5)
    edges = 0
    for _ in range(40):
        a, b = random_configurations(robot, rng, 2)
        edge = a + np.linspace(0.0, 1.0, 30)[:, None] * (b - a)
        uncertain = np.ones((len(edge), len(world.pairs)), dtype=bool)
        pairs = np.arange(len(world.pairs))
        every, ordered = (tests.violated(edge, uncertain, pairs, 0.05, ordered=o) for o in (False, True))
        first = int(np.argmax(every)) if every.any() else len(edge)
        np.testing.assert_array_equal(ordered[:first], every[:first])
        assert ordered[first:].all()
        edges += 0 < first < len(edge) - 1
    assert edges >= 5  # edges blocked part way along occur


def test_a_pair_flagged_on_its_hull_is_decided_on_its_mesh() -> None:
    robot = ck.load_robot(UR5)
    obstacles = [ck.Obstacle.box((0.2, 0.2, 0.2), (0.5, 0.0, 0.3)), ck.Obstacle.sphere(0.1, (0.2, 0.4, 0.5))]
    world = ck.CollisionWorld(robot, obstacles)
    hulls_world = world.on_hulls()
    q = np.random.default_rng(6).uniform(robot.limits.lower, robot.limits.upper, (1000, robot.nq))
    on_meshes, on_hulls = world.min_clearance_batch(q)[0], hulls_world.min_clearance_batch(q)[0]
    tests = ObstacleTests(
        robot.model, world.geometry_model, ExactPairs(world.geometry_model, robot.exact_meshes)
    )
    uncertain, pairs = np.ones((len(q), len(world.pairs)), dtype=bool), np.arange(len(world.pairs))
    cleared_on_meshes = 0
    for margin_m in (0.0, 0.01, 0.02):
        np.testing.assert_array_equal(tests.violated(q, uncertain, pairs, margin_m), on_meshes < margin_m)
        hulls = tests.on_hulls().violated(q, uncertain, pairs, margin_m)
        np.testing.assert_array_equal(hulls, on_hulls < margin_m)
        cleared_on_meshes += int(np.sum(hulls & (on_meshes >= margin_m)))
    assert cleared_on_meshes >= 5  # the meshes clear what the hulls do not


def test_margins_beyond_those_kept_are_set_again(cluttered: ck.CollisionWorld) -> None:
    world = cluttered
    tests = ObstacleTests(world.robot.model, world.geometry_model)
    q = random_configurations(world.robot, np.random.default_rng(8), 100)
    uncertain, pairs = np.ones((len(q), len(world.pairs)), dtype=bool), np.arange(len(world.pairs))
    margins = np.linspace(0.0, 0.1, MAX_MARGINS + 3)
    first = [tests.violated(q, uncertain, pairs, m) for m in margins]
    again = [tests.violated(q, uncertain, pairs, m) for m in margins[::-1]][::-1]
    for a, b, m in zip(first, again, margins, strict=True):
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, world.min_clearance_batch(q)[0] < m)


def test_the_meshes_are_not_asked_where_a_pair_without_one_is_within_the_margin(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    ur5 = ck.load_robot(UR5)
    forearm = {g: mesh for g, mesh in ur5.exact_meshes.items() if ur5.geometries[g].name == "forearm_link"}
    robot = dataclasses.replace(ur5, exact_meshes=forearm)  # the other links' hulls decide alone
    obstacles = [ck.Obstacle.box((0.2, 0.2, 0.2), (0.5, 0.0, 0.3)), ck.Obstacle.sphere(0.1, (0.2, 0.4, 0.5))]
    world = ck.CollisionWorld(robot, obstacles)
    exact = ExactPairs(world.geometry_model, robot.exact_meshes)
    q = np.random.default_rng(8).uniform(robot.limits.lower, robot.limits.upper, (400, robot.nq))
    margin_m = 0.02
    on_hulls = pair_distances(world.on_hulls(), q)
    hull_decides = np.any(on_hulls[:, ~exact.refined] < margin_m, axis=1)
    asked: list[np.ndarray] = []
    violated = ExactPairs.violated

    def recorded(self: ExactPairs, *args: object, **kwargs: object) -> np.ndarray:
        asked.extend(np.asarray(args[4]))
        return violated(self, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(ExactPairs, "violated", recorded)
    tests = ObstacleTests(robot.model, world.geometry_model, exact)
    uncertain, pairs = np.ones((len(q), len(world.pairs)), dtype=bool), np.arange(len(world.pairs))
    found = tests.violated(q, uncertain, pairs, margin_m)
    np.testing.assert_array_equal(found, world.min_clearance_batch(q)[0] < margin_m)
    rows = {tuple(x) for x in q[hull_decides].tolist()}
    assert asked and hull_decides.sum() > 20  # the meshes were asked, elsewhere
    assert not any(tuple(x) in rows for x in np.asarray(asked).tolist())
