from __future__ import annotations

import numpy as np

import cpr_kin as ck
from cpr_kin.bounds.obstacle_blocks import BOX_PADDING_M, obstacle_blocks
from cpr_kin.bounds.obstacle_bounds import obstacle_arrays
from cpr_kin.bounds.pair_bounds import PairBounds

from .conftest import random_configurations
from .test_collision import random_obstacle

SHAPES = ("box", "sphere", "cylinder", "capsule")


def scattered(rng: np.random.Generator, count: int) -> list[ck.Obstacle]:
    obstacles = [random_obstacle(SHAPES[k % 4], rng) for k in range(count)]
    return [ck.Obstacle(**{**o.__dict__, "name": f"o{k}"}) for k, o in enumerate(obstacles)]


def test_blocks_partition_the_pairs_and_hold_their_obstacles(rng: np.random.Generator) -> None:
    obstacles = scattered(rng, 23)
    shapes = obstacle_arrays(obstacles)
    pair_capsule = np.repeat(np.arange(5), 21)  # each capsule against most obstacles, one set skipped
    pair_obstacle = np.concatenate([np.delete(np.arange(23), [c, c + 1]) for c in range(5)])
    blocks = obstacle_blocks(pair_capsule, pair_obstacle, shapes.centre, shapes.extent, cluster_size=4)
    assert sorted(blocks.order.tolist()) == list(range(len(pair_capsule)))  # every pair once
    assert blocks.start[0] == 0 and blocks.start[-1] == len(pair_capsule)
    assert np.all(np.diff(blocks.start) >= 1)
    low = shapes.centre - shapes.extent
    high = shapes.centre + shapes.extent
    clusters: dict[bytes, set[int]] = {}  # a cluster's obstacles, by its box
    for b in range(len(blocks.capsule)):
        pairs = blocks.order[blocks.start[b] : blocks.start[b + 1]]
        assert np.all(pair_capsule[pairs] == blocks.capsule[b])
        held = pair_obstacle[pairs]
        assert np.all(blocks.box[b, 0] <= low[held] - BOX_PADDING_M / 2)
        assert np.all(high[held] + BOX_PADDING_M / 2 <= blocks.box[b, 1])
        clusters.setdefault(blocks.box[b].tobytes(), set()).update(held.tolist())
    assert all(1 <= len(members) <= 4 for members in clusters.values())
    assert sum(len(members) for members in clusters.values()) == 23  # the clusters partition them
    for c in range(5):  # a capsule's pairs with one cluster make one block
        boxes = [blocks.box[b].tobytes() for b in np.flatnonzero(blocks.capsule == c)]
        assert len(boxes) == len(set(boxes)) >= len(clusters) - 2


def test_no_pairs_no_blocks(rng: np.random.Generator) -> None:
    shapes = obstacle_arrays(scattered(rng, 3))
    none = np.zeros(0, dtype=np.int64)
    blocks = obstacle_blocks(none, none, shapes.centre, shapes.extent)
    assert len(blocks.capsule) == 0 and blocks.start.tolist() == [0] and len(blocks.order) == 0


def test_margin_tests_by_blocks_are_the_bounds_answer_among_many_obstacles(
    robot: ck.Robot, rng: np.random.Generator
) -> None:
    # forty obstacles: most blocks lie far from a capsule and are skipped whole; what is
    # flagged is still exactly where a pair's bound (computed without blocks) is below
    obstacles = scattered(rng, 40)
    pairs = [(g.index, k) for g in robot.geometries for k in range(len(obstacles))]
    bounds = PairBounds(robot.model, robot.collision_model, obstacles, pairs)
    configurations = random_configurations(robot, rng, 300)
    per_pair = bounds(configurations)
    for threshold in (0.0, 0.02, 0.1):
        flagged = bounds.pairs_below(configurations, threshold)
        np.testing.assert_array_equal(flagged, per_pair <= threshold)
        np.testing.assert_array_equal(bounds.any_below(configurations, threshold), flagged.any(axis=1))
        assert flagged.any() and not flagged.all(axis=1).any()
