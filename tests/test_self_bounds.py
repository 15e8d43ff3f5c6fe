"""Cheap bounds of a robot's own pair distances: below coal's, and a screen that changes no answer."""

from __future__ import annotations

import dataclasses
import itertools

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.bounds.batch_kinematics import sampled_configurations
from cpr_kin.bounds.segments import segment_distance
from cpr_kin.bounds.self_bounds import SelfPairBounds
from cpr_kin.collision.self_collision import SelfCollision
from cpr_kin.collision.self_screen import ScreenedSelfTest
from cpr_kin.collision.self_split import (
    NEAR_SHARE,
    PROBES,
    SCREEN_THRESHOLDS_M,
    SelfScreen,
    robot_self_screen,
    screen_threshold,
)
from cpr_kin.model.packages import example_robot_data_share

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
ROBOTS = SHARE / "example-robot-data" / "robots"


def brute_distance(p: np.ndarray, q: np.ndarray, count: int = 401) -> float:
    u = np.linspace(0.0, 1.0, count)[:, None]
    a, b = p[0] + u * (p[1] - p[0]), q[0] + u * (q[1] - q[0])
    return float(np.sqrt(((a[:, None] - b[None]) ** 2).sum(axis=-1)).min())


def test_the_segments_distance_is_their_closest_points(seed: int = 0) -> None:
    rng = np.random.default_rng(seed)
    for case in range(200):
        p, q = rng.normal(size=(2, 2, 3))
        if case % 5 == 1:  # parallel, overlapping or not
            q[1] = q[0] + (p[1] - p[0]) * rng.uniform(-2.0, 2.0)
        if case % 7 == 2:  # a point
            p[1] = p[0]
        exact = segment_distance(p, q)
        brute = brute_distance(p, q)
        assert exact <= brute + 1e-12  # never above a distance actually attained
        assert brute - exact < 1e-2  # and the brute force's grid comes close to it
    crossing = np.array([[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]], [[0.0, -1.0, 0.5], [0.0, 1.0, 0.5]]])
    assert segment_distance(*crossing) == pytest.approx(0.5, abs=1e-15)


ARMS = ["panda_description/urdf/panda.urdf", "ur_description/urdf/ur5_robot.urdf"]


@pytest.fixture(scope="module", params=ARMS)
def arm(request: pytest.FixtureRequest) -> ck.Robot:
    return ck.load_robot(ROBOTS / request.param)


def test_the_bounds_are_below_coals_distances(arm: ck.Robot) -> None:
    collision = ck.CollisionWorld(arm, []).self_collision
    pairs = collision._pairs
    names = [g.name for g in arm.geometries]
    bounds = SelfPairBounds(arm.model, collision.geometry_model, pairs)
    q = np.random.default_rng(1).uniform(arm.limits.lower, arm.limits.upper, (200, arm.nq))
    below = bounds(q)
    np.testing.assert_array_less(below.min(axis=1), collision.distances(q)[0] + 1e-9)
    # within a threshold, the boxes' bound where larger (tighter); beyond it, the spheres' (looser)
    far = bounds(q, threshold_m=0.0)
    apart = below > 0.0
    assert np.all(far[apart] <= below[apart] + 1e-12) and np.all(far[~apart] >= below[~apart] - 1e-12)
    for k in range(0, len(pairs), 7):  # every 7th pair on its own against coal's distance
        exact = SelfCollision(arm.model, arm.collision_model, (pairs[k],), names).distances(q)[0]
        np.testing.assert_array_less(below[:, k], exact + 1e-9)
        np.testing.assert_array_less(far[:, k], exact + 1e-9)
    for k in range(len(pairs)):  # one pair's column, its two capsules alone placed: the same bits
        np.testing.assert_array_equal(bounds.column(q, k), below[:, k])


@pytest.mark.parametrize("margin_m", [0.0, 0.01, 0.05])
def test_the_screen_gives_coals_answer(arm: ck.Robot, margin_m: float) -> None:
    collision = ck.CollisionWorld(arm, []).self_collision
    test = ScreenedSelfTest(arm.model, collision.geometry_model, collision._pairs, 2, exact=collision._exact)
    assert len(test.near_pairs) + test.far_bounds.n_pairs == len(collision._pairs)
    q = np.random.default_rng(2).uniform(arm.limits.lower, arm.limits.upper, (500, arm.nq))
    distance, _ = collision.distances(q)
    violated = test.violated(q, margin_m)
    np.testing.assert_array_equal(violated, distance < margin_m)
    one_by_one = [test.violated(x[None], margin_m)[0] for x in q[:100]]  # no thread pool
    np.testing.assert_array_equal(one_by_one, violated[:100])
    # in small batches, another margin between them: the far pairs tested change every call
    in_fives = []
    for k in range(0, 200, 5):
        in_fives.append(test.violated(q[k : k + 5], margin_m))
        test.violated(q[k + 300 : k + 305], margin_m + 0.02)
    np.testing.assert_array_equal(np.concatenate(in_fives), violated[:200])


@pytest.mark.parametrize("hulls_margin_m", [0.001, 0.01, 0.03])
def test_a_hulls_copy_leaves_the_originals_answers_coals(arm: ck.Robot, hulls_margin_m: float) -> None:
    # the copy shares coal's pools: what it sets them to (margin, far pairs) the original must know
    world = ck.CollisionWorld(arm, [])
    collision = world.self_collision
    q = np.random.default_rng(4).uniform(arm.limits.lower, arm.limits.upper, (600, arm.nq))
    distance, _ = collision.distances(q[:300])
    margin_m = 0.01
    np.testing.assert_array_equal(collision.violated(q[:300], margin_m), distance < margin_m)
    hulls = world.on_hulls().self_collision
    hulls.violated(q[300:], hulls_margin_m)  # another margin, or the same with other far pairs
    np.testing.assert_array_equal(collision.violated(q[:300], margin_m), distance < margin_m)


def test_the_screened_distances_are_coals_over_every_pair(arm: ck.Robot) -> None:
    # on the hulls alone (test_exact_pairs holds the meshes to another library)
    arm = dataclasses.replace(arm, exact_meshes={})
    collision = ck.CollisionWorld(arm, []).self_collision
    q = np.random.default_rng(3).uniform(arm.limits.lower, arm.limits.upper, (300, arm.nq))
    model, geometry_model = arm.model, collision.geometry_model
    data, gdata = model.createData(), geometry_model.createData()  # every pair active
    expected = np.empty(len(q))
    for k, x in enumerate(q):  # read each result before the next call overwrites it
        pair = pin.computeDistances(model, data, geometry_model, gdata, x)
        expected[k] = gdata.distanceResults[pair].min_distance
    distance, closest = collision.distances(q)
    # coal's GJK starts from the pair's last answer: the order of queries moves results by ~1e-8
    np.testing.assert_allclose(distance, expected, rtol=0.0, atol=1e-6)
    pairs = geometry_model.collisionPairs
    for k in range(0, len(q), 37):  # the pair named is one at that distance
        a, b = pairs[int(closest[k])].first, pairs[int(closest[k])].second
        assert (a, b) in collision._pairs


def test_a_robots_screen_is_built_once_for_each_set_of_pairs(arm: ck.Robot) -> None:
    first, again = (ck.CollisionWorld(arm, []).self_collision for _ in range(2))
    assert robot_self_screen(arm, first._pairs, 0.01) is robot_self_screen(arm, again._pairs, 0.01)
    links = [g.link for g in arm.geometries]
    a, b = first._pairs[0]
    fewer = ck.CollisionWorld(arm, [], allowed_pairs=[(links[a], links[b])]).self_collision
    screen = robot_self_screen(arm, fewer._pairs, 0.01)
    assert screen is not robot_self_screen(arm, first._pairs, 0.01)
    assert screen.all_bounds.n_pairs == len(fewer._pairs) < len(first._pairs)
    # the same split as one built afresh for those pairs
    fresh = SelfScreen.build(arm.model, arm.collision_model, fewer._pairs, screen_threshold(0.01))
    np.testing.assert_array_equal(screen.near, fresh.near)
    # one screen per threshold: margins that round to the same one share it
    assert robot_self_screen(arm, first._pairs, 0.006) is robot_self_screen(arm, first._pairs, 0.01)
    assert robot_self_screen(arm, first._pairs, 0.0) is not robot_self_screen(arm, first._pairs, 0.01)


def test_the_screens_threshold_is_twice_the_margin_rounded_up_its_ladder() -> None:
    assert [screen_threshold(m) for m in (0.0, 0.001, 0.0011, 0.01, 0.03, 0.6)] == [
        0.002,
        0.002,
        0.005,
        0.02,
        0.1,
        SCREEN_THRESHOLDS_M[-1],
    ]
    assert all(screen_threshold(t / 2) == t for t in SCREEN_THRESHOLDS_M)


def test_a_smaller_threshold_leaves_no_more_pairs_near(arm: ck.Robot) -> None:
    pairs = ck.CollisionWorld(arm, []).self_collision._pairs
    near = [SelfScreen.build(arm.model, arm.collision_model, pairs, t).near for t in SCREEN_THRESHOLDS_M]
    for smaller, larger in itertools.pairwise(near):  # a bound within t is within any larger t
        assert not np.any(smaller & ~larger)


def test_a_pair_mostly_near_without_a_grid_is_screened_as_a_far_one(arm: ck.Robot) -> None:
    collision = ck.CollisionWorld(arm, []).self_collision
    pairs = collision._pairs
    threshold_m = SCREEN_THRESHOLDS_M[-1]  # 1 m: most pairs' bounds are in doubt, far along the chain too
    screen = SelfScreen.build(arm.model, arm.collision_model, pairs, threshold_m)
    probes = sampled_configurations(arm.model, PROBES, np.random.default_rng(0))
    mostly = (screen.all_bounds(probes, threshold_m) <= threshold_m).mean(axis=0) > NEAR_SHARE
    near = [p for p, n in zip(pairs, screen.near, strict=True) if n]
    assert near and not np.any(screen.near & ~mostly)
    assert list(screen.near_cells.pairs) == near and screen.near_cells.grids is not None  # each with a grid
    gridless = mostly & ~screen.near  # those more than two joints apart
    assert gridless.any() and screen.far_bounds.n_pairs == len(pairs) - len(near)
    # coal's answer still
    model, geometry_model, exact = arm.model, collision.geometry_model, collision._exact
    test = ScreenedSelfTest(model, geometry_model, pairs, 2, screen=screen, exact=exact)
    q = np.random.default_rng(6).uniform(arm.limits.lower, arm.limits.upper, (300, arm.nq))
    distance, _ = collision.distances(q)
    for margin_m in (0.0, 0.01, 0.3):
        np.testing.assert_array_equal(test.violated(q, margin_m), distance < margin_m)
