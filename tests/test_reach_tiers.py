"""The pairs' bounds in tiers of reach distance: lower bounds of coal's, each group's least unchanged."""

from __future__ import annotations

import gc
import weakref
from dataclasses import dataclass

import numpy as np
import pytest

import cpr_kin as ck
import cpr_kin.collision.reach_tiers as reach_tiers
from cpr_kin.bounds.obstacle_bounds import obstacle_arrays
from cpr_kin.bounds.pair_bounds import PairBounds
from cpr_kin.collision.decisive import below_coal
from cpr_kin.collision.reach_tiers import ReachTiers
from cpr_kin.collision.robot_reach import (
    PairReach,
    WorldPairs,
    pair_reach_distances,
    robot_pair_bounds,
    sphere_reach_distances,
)
from cpr_kin.collision.touch_links import checked_pairs
from cpr_kin.model.robot import GROUPS

from .conftest import random_configurations


def room(seed: int) -> list[ck.Obstacle]:
    """A crate and a ball within the CPR's reach, then 150 boxes of a room's clutter 1.3-3 m out."""
    rng = np.random.default_rng(seed)
    near = [
        ck.Obstacle.box((0.3, 0.3, 0.3), (0.0, 0.6, 0.15), name="crate"),
        ck.Obstacle.sphere(0.1, (0.2, 0.6, 0.4), name="ball"),
    ]
    far = []
    for k in range(150):
        radius, angle = rng.uniform(1.3, 3.0), rng.uniform(0.0, 2 * np.pi)
        centre = (radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0.0, 1.5))
        size, rpy = tuple(rng.uniform(0.05, 0.4, 3)), tuple(rng.uniform(-3, 3, 3))
        far.append(ck.Obstacle.box(size, centre, rpy, name=f"b{k}"))
    return near + far


class CountedBounds:
    """A pair set's bounds that count the configurations they bound."""

    def __init__(self, bounds: PairBounds) -> None:
        self.bounds, self.rows = bounds, 0

    def __call__(self, q: np.ndarray) -> np.ndarray:
        self.rows += len(q)
        return self.bounds(q)


@dataclass(frozen=True)
class RoomPairs:
    """The room's obstacles, the CPR's pairs with them, their reach distances [m] and groups."""

    obstacles: list[ck.Obstacle]
    pairs: list[tuple[int, int]]
    reach_m: np.ndarray
    group: np.ndarray


@pytest.fixture(scope="module")
def room_pairs(robot: ck.Robot) -> RoomPairs:
    obstacles = room(3)
    pairs = checked_pairs(robot, obstacles)
    group = np.array([GROUPS.index(robot.geometries[g].group) for g, _ in pairs])
    reach = sphere_reach_distances(robot, obstacle_arrays(obstacles), pairs)
    return RoomPairs(obstacles, pairs, reach, group)


def tiers_of(robot: ck.Robot, parts: RoomPairs, counted: dict[tuple[bool, ...], CountedBounds]) -> ReachTiers:
    shapes = obstacle_arrays(parts.obstacles)

    def bounds_of(active: tuple[bool, ...]) -> CountedBounds:
        chosen = [pair for pair, on in zip(parts.pairs, active, strict=True) if on]
        counted[active] = CountedBounds(robot_pair_bounds(robot, parts.obstacles, chosen, shapes))
        return counted[active]

    return ReachTiers(parts.reach_m, parts.group, bounds_of)  # type: ignore[arg-type]  # called alike


@pytest.mark.parametrize("min_tier_pairs", [1, reach_tiers.MIN_TIER_PAIRS, 10**6])
def test_each_groups_least_is_every_pairs_and_far_tiers_are_bounded_only_where_they_may_be_least(
    robot: ck.Robot,
    room_pairs: RoomPairs,
    rng: np.random.Generator,
    monkeypatch: pytest.MonkeyPatch,
    min_tier_pairs: int,
) -> None:
    """Oracle: every pair bounded in one set, each floored by its reach distance. However the tiers
    are cut (one pair a tier at least, the default, one tier), each group's least is the oracle's,
    its tiers beyond the nearest bounded only where they may hold it; every pair's bound is the
    oracle's."""
    monkeypatch.setattr(reach_tiers, "MIN_TIER_PAIRS", min_tier_pairs)
    obstacles, reach, group = room_pairs.obstacles, room_pairs.reach_m, room_pairs.group
    q = random_configurations(robot, rng, 300)
    every = robot_pair_bounds(robot, obstacles, room_pairs.pairs, obstacle_arrays(obstacles))(q)
    every = np.maximum(every, reach)
    counted: dict[tuple[bool, ...], CountedBounds] = {}
    tiers = tiers_of(robot, room_pairs, counted)
    for g in range(len(GROUPS)):
        columns = tiers.columns(g)
        np.testing.assert_array_equal(columns, np.flatnonzero(group == g))
        np.testing.assert_array_equal(tiers.group_least(q, g), every[:, columns].min(axis=1))
    rows = [c.rows for c in counted.values()]  # of the least's, tier by tier, nearest first per group
    if min_tier_pairs == 10**6:  # one tier per group, bounded everywhere
        assert rows == [len(q)] * len(GROUPS)
    else:  # the clutter out of reach is bounded at a share of the configurations
        assert len(rows) > 2 * len(GROUPS) and sum(rows) < 0.7 * len(rows) * len(q)
        assert rows[-1] == 0 and 0 in rows[:-1]  # each group's farthest tier: nowhere
    for g in range(len(GROUPS)):  # every pair's bound, as the search for the closest one visits them
        columns = tiers.columns(g)
        np.testing.assert_array_equal(tiers.group_bounds(q, g), every[:, columns])


def test_world_pair_bounds_are_below_coal_and_above_reach(robot: ck.Robot, rng: np.random.Generator) -> None:
    """In a world of a room's clutter: every pair's bound at most coal's distance (where positive),
    at least its reach distance; each group's lower bound at most its clearance."""
    world = ck.CollisionWorld(robot, room(4))
    q = random_configurations(robot, rng, 40)
    bounds = world.pair_bounds(q)
    assert bounds.shape == (len(q), len(world.pairs))
    exact = np.array([[p.distance_m for p in world.clearance(c).pairs] for c in q])
    positive = bounds > 0.0
    assert np.all(below_coal(bounds[positive]) <= exact[positive])
    obstacles = world.obstacles
    reach = sphere_reach_distances(robot, obstacle_arrays(obstacles), checked_pairs(robot, obstacles))
    assert np.all(bounds >= reach)
    assert np.all(world.clearance_lower_bounds(q) <= world.clearance_batch(q).clearance_m)
    for g in range(len(GROUPS)):  # the group's closest pair, found on the tiers' bounds, is coal's least
        distance, _ = world.group_clearance(q, g)
        columns = [k for k, (_, _, group) in enumerate(world.pairs) if group == GROUPS[g]]
        np.testing.assert_allclose(distance, exact[:, columns].min(axis=1), atol=2e-6)


def test_a_used_world_is_freed_when_dropped_without_the_garbage_collector(
    robot: ck.Robot, rng: np.random.Generator
) -> None:
    """No reference cycle holds a world's arrays (its tiers once held a method of the world: among
    400 boxes, a benchmark's process grew to 1.3 GB between collections)."""
    world = ck.CollisionWorld(robot, room(5))
    q = random_configurations(robot, rng, 8)
    world.clearance_lower_bounds(q)
    world.group_clearance(q, 0)
    world.on_hulls().clearance_lower_bounds(q)
    dropped = weakref.ref(world)
    enabled = gc.isenabled()
    gc.disable()
    try:
        del world
        assert dropped() is None
    finally:
        if enabled:
            gc.enable()


def test_the_spheres_bound_coals_reach_and_within_asks_coal_only_of_the_pairs_they_leave_in(
    robot: ck.Robot, room_pairs: RoomPairs, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Oracle: coal's distance from the swept capsules to every obstacle. The spheres' bound is at
    most it where positive; ``within`` says what comparing coal's with the distance says, for
    distances from none to every pair, and coal measures only the pairs the spheres leave in."""
    import cpr_kin.collision.robot_reach as robot_reach

    obstacles, pairs = room_pairs.obstacles, room_pairs.pairs
    coal_m = pair_reach_distances(robot, obstacles, pairs)
    sphere_m = room_pairs.reach_m
    np.testing.assert_array_equal(sphere_m, sphere_reach_distances(robot, obstacle_arrays(obstacles), pairs))
    positive = sphere_m > 0.0
    assert np.all(sphere_m[positive] <= coal_m[positive] + 1e-9)
    assert np.sum(sphere_m > 0.2) > 0.8 * len(pairs)  # the clutter is out of reach, by the spheres too
    measured: list[int] = []

    def counted(robot: ck.Robot, obstacles: list[ck.Obstacle], chosen: list[tuple[int, int]]) -> np.ndarray:
        measured.append(len(chosen))
        return pair_reach_distances(robot, obstacles, chosen)

    monkeypatch.setattr(robot_reach, "pair_reach_distances", counted)
    reach = PairReach(WorldPairs(robot, obstacles, pairs, obstacle_arrays(obstacles)))
    for distance_m in (-0.01, 0.0, 0.02, 0.1, 0.3, 1.0, np.inf):
        np.testing.assert_array_equal(reach.within(distance_m), coal_m <= distance_m)
    assert sum(measured) < 0.3 * len(pairs)  # each pair at most once, the far ones never
