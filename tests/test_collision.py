from __future__ import annotations

import dataclasses
import functools
import os
from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import minimize

import cpr_kin as ck
from cpr_kin.collision.coal_pools import default_threads
from cpr_kin.collision.robot_reach import pair_reach_distances
from cpr_kin.collision.touch_links import checked_pairs

from .conftest import PAPER_GOAL_TCP, PAPER_START_TCP, random_configurations


def pair(clearance: ck.Clearance, geometry: str) -> ck.PairDistance:
    return next(p for p in clearance.pairs if p.robot_geometry == geometry)


def test_arm_beam_straight_above_a_box(robot: ck.Robot) -> None:
    # theta1 = 0, d2 = 0.5 (arm axis z_c = 0.75), d3 = 0.5 (beam spans x in [0.1, 0.8]);
    # a 0.1 x 0.1 x 0.2 block under the beam's middle, top at z = 0.6:
    # gap = 0.75 - 0.025 - 0.6; every other link is farther away
    world = ck.CollisionWorld(robot, [ck.Obstacle.box((0.1, 0.1, 0.2), (0.45, 0.0, 0.5), name="block")])
    clearance = world.clearance([0.0, 0.5, 0.5, 0.0, 0.0])
    arm = pair(clearance, "arm")
    assert arm.distance_m == pytest.approx(0.125, abs=1e-9)
    assert arm.point_on_robot[2] == pytest.approx(0.725, abs=1e-9)
    assert arm.point_on_obstacle[2] == pytest.approx(0.6, abs=1e-9)
    assert clearance.group_clearance_m["links"] == pytest.approx(0.125, abs=1e-9)
    assert clearance.closest is not None and clearance.closest.robot_geometry == "arm"


def test_tool_beside_a_sphere(robot: ck.Robot) -> None:
    # theta1 = 0, d3 = 0.2 -> tool spans x in [0.48, 0.52]; sphere r = 0.05 whose surface is
    # 0.1 m beyond the tool's front face, level with the tool's middle
    q = [0.0, 0.3, 0.2, 0.0, 0.0]
    z_mid = 0.25 + 0.3 - 0.075
    world = ck.CollisionWorld(robot, [ck.Obstacle.sphere(0.05, (0.52 + 0.1 + 0.05, 0.0, z_mid), name="ball")])
    clearance = world.clearance(q)
    assert pair(clearance, "tool").distance_m == pytest.approx(0.1, abs=1e-9)
    assert clearance.group_clearance_m["effector"] == pytest.approx(0.1, abs=1e-9)
    assert clearance.violating_groups(0.1 + 1e-6) == ("effector",)
    assert clearance.violating_groups(0.1 - 1e-6) == ()


def test_obstacle_behind_a_retracted_arm_is_hit_only_by_the_rear_end(robot: ck.Robot) -> None:
    # theta1 = 0, d3 = 0: the beam spans x in [-0.40, 0.30] at z_c; a 0.1 m cube centred at
    # x = -0.35 on the arm axis swallows the rear end
    z_c = 0.25 + 0.3
    world = ck.CollisionWorld(robot, [ck.Obstacle.box((0.1, 0.1, 0.1), (-0.35, 0.0, z_c), name="shelf")])
    retracted = world.clearance([0.0, 0.3, 0.0, 0.0, 0.0])
    # smallest escape of the 0.05 x 0.05 beam from the 0.1 cube: 0.075 sideways or vertically
    assert pair(retracted, "arm").distance_m == pytest.approx(-0.075, abs=1e-6)
    assert retracted.violating_groups(0.1) == ("links",)
    # the wrist (radius 0.035 about the flange at x = 0.30) is 0.265 + 0.30 from the cube
    assert retracted.group_clearance_m["effector"] == pytest.approx(0.565, abs=1e-9)
    for geometry in ("carriage", "column", "base"):
        assert pair(retracted, geometry).distance_m > 0.1
    # extended by 0.3 m, the rear end sits at x = -0.1: 0.2 m from the cube's face
    extended = world.clearance([0.0, 0.3, 0.3, 0.0, 0.0])
    assert pair(extended, "arm").distance_m == pytest.approx(0.2, abs=1e-9)


def test_paper_start_goal_clear_and_swing_collides(robot: ck.Robot, paper_world: ck.CollisionWorld) -> None:
    start, goal = ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP)
    assert paper_world.clearance(start).min_clearance_m > 0.1
    assert paper_world.clearance(goal).min_clearance_m > 0.1
    # constant-height swing: theta1 sweeps from start to goal, d2 and d3 held
    swing = np.linspace(start, goal, 101)
    batch = paper_world.clearance_batch(swing)
    assert batch.min_clearance_m.min() < 0.0  # the tool passes through the crate
    # mid-swing the tool tip is inside the crate and the beam (bottom at z = 0.4 - 0.025)
    # passes 0.075 m above the crate's top (z = 0.3)
    middle = paper_world.clearance(swing[50])
    assert middle.group_clearance_m["effector"] < 0.0
    assert middle.group_clearance_m["links"] == pytest.approx(0.075, abs=1e-6)
    assert middle.violating_groups(0.1) == ("effector", "links")


def test_batch_agrees_with_single(
    robot: ck.Robot, paper_world: ck.CollisionWorld, rng: np.random.Generator
) -> None:
    configurations = random_configurations(robot, rng, 100)
    batch = paper_world.clearance_batch(configurations)
    pairs = paper_world.pairs
    for k, q in enumerate(configurations):
        single = paper_world.clearance(q)
        for g, group in enumerate(ck.GROUPS):
            assert batch.clearance_m[k, g] == pytest.approx(single.group_clearance_m[group], abs=1e-6)
            assert pairs[batch.closest_pair[k, g]][2] == group


def test_margin_violated_agrees_with_distances(
    robot: ck.Robot, paper_world: ck.CollisionWorld, rng: np.random.Generator
) -> None:
    configurations = random_configurations(robot, rng, 1000)
    distances = paper_world.clearance_batch(configurations).min_clearance_m
    for margin in (0.0, 0.1, 0.25):
        violated = paper_world.margin_violated(configurations, margin)
        ambiguous = np.abs(distances - margin) < 1e-6
        np.testing.assert_array_equal(violated[~ambiguous], distances[~ambiguous] < margin)
        assert 0 < violated.sum() < len(configurations)


@pytest.mark.parametrize("threads", [1, 2])
def test_margin_violated_among_several_obstacles_agrees_with_distances(
    robot: ck.Robot, rng: np.random.Generator, threads: int
) -> None:
    """Each configuration goes to coal only for the obstacles its bounds leave uncertain: same answer.

    On one thread and on two (coal's parallel batches), whatever the machine's default.
    """
    world = ck.CollisionWorld(
        robot,
        [
            ck.Obstacle.box(size=(0.3, 0.3, 0.3), xyz=(0.0, 0.6, 0.15), name="crate"),
            ck.Obstacle.cylinder(radius=0.05, length=0.8, xyz=(0.4, 0.2, 0.4), name="pillar"),
            ck.Obstacle.sphere(radius=0.1, xyz=(-0.3, 0.3, 0.5), name="ball"),
        ],
        num_threads=threads,
    )
    assert world.num_threads == threads
    configurations = random_configurations(robot, rng, 1000)
    distances = world.clearance_batch(configurations).min_clearance_m
    for margin in (0.0, 0.05, 0.1, 0.05):  # a margin set again reuses the pools
        violated = world.margin_violated(configurations, margin)
        ambiguous = np.abs(distances - margin) < 1e-6
        np.testing.assert_array_equal(violated[~ambiguous], distances[~ambiguous] < margin)
        assert 0 < violated.sum() < len(configurations)
        one_by_one = [world.margin_violated(q[None], margin)[0] for q in configurations[:200]]
        np.testing.assert_array_equal(one_by_one, violated[:200])  # one configuration: no thread pool


@pytest.mark.parametrize(("cores", "threads"), [(1, 1), (2, 1), (3, 2), (64, 2)])
def test_default_threads_leave_a_core_to_the_machine(
    robot: ck.Robot, monkeypatch: pytest.MonkeyPatch, cores: int, threads: int
) -> None:
    """A second thread only where a third core is left: on 2 busy cores it waits time slices."""
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: set(range(cores)), raising=False)
    assert default_threads() == threads
    assert ck.CollisionWorld(robot, []).num_threads == threads
    assert ck.CollisionWorld(robot, [], num_threads=2).num_threads == 2  # asked for: given


def test_world_without_obstacles(robot: ck.Robot) -> None:
    world = ck.CollisionWorld(robot, [])
    assert world.clearance(np.zeros(5)).min_clearance_m == np.inf
    assert np.all(world.clearance_batch(np.zeros((3, 5))).clearance_m == np.inf)
    assert not world.margin_violated(np.zeros((3, 5)), 0.1).any()


def test_duplicate_obstacle_names(robot: ck.Robot) -> None:
    box = ck.Obstacle.box((0.1, 0.1, 0.1), (1, 1, 1), name="crate")
    with pytest.raises(ck.CprKinError, match=r"\['crate'\] appear more than once"):
        ck.CollisionWorld(robot, [box, box])


def test_bad_batch(paper_world: ck.CollisionWorld) -> None:
    with pytest.raises(ck.CprKinError, match=r"expected \(N, 5\)"):
        paper_world.clearance_batch(np.zeros((4, 3)))
    with pytest.raises(ck.CprKinError, match="NaN"):
        paper_world.clearance_batch(np.full((2, 5), np.nan))
    with pytest.raises(ck.CprKinError, match="safety margin -1"):
        paper_world.margin_violated(np.zeros((2, 5)), -1.0)


# --- independent oracle: the separating-axis dual with analytic support functions ---------
# For disjoint convex sets A and B, dist(A, B) = max over unit n of -h_A(-n) - h_B(n), where
# h_X(d) = max over x in X of d.x. Exact for the primitives below (no faceting) and unrelated
# to coal's GJK/EPA.


def support(geometry: Any, placement: Any) -> Callable[[np.ndarray], float]:
    centre, rotation = np.asarray(placement.translation), np.asarray(placement.rotation)
    axis = rotation[:, 2]
    kind = type(geometry).__name__
    if kind == "Box":
        half = np.asarray(geometry.halfSide)
        return lambda d: float(centre @ d + np.abs(rotation.T @ d) @ half)
    if kind == "Sphere":
        return lambda d: float(centre @ d + geometry.radius * np.linalg.norm(d))
    if kind == "Cylinder":
        r, h = geometry.radius, geometry.halfLength
        return lambda d: float(centre @ d + h * abs(axis @ d) + r * np.linalg.norm(d - (axis @ d) * axis))
    if kind == "Capsule":
        r, h = geometry.radius, geometry.halfLength
        return lambda d: float(centre @ d + h * abs(axis @ d) + r * np.linalg.norm(d))
    raise AssertionError(kind)


def separating_distance(
    h_a: Callable[[np.ndarray], float],
    h_b: Callable[[np.ndarray], float],
    start: np.ndarray,
    rng: np.random.Generator,
) -> float:
    def negative_gap(n: np.ndarray) -> float:
        n = n / np.linalg.norm(n)
        return h_a(-n) + h_b(n)

    options = {"xatol": 1e-12, "fatol": 1e-14, "maxiter": 4000}
    starts = [start, *rng.normal(size=(2, 3))]
    best = min(
        (minimize(negative_gap, s, method="Nelder-Mead", options=options) for s in starts),
        key=lambda r: r.fun,
    )
    polished = minimize(negative_gap, best.x / np.linalg.norm(best.x), method="Nelder-Mead", options=options)
    return -float(min(best.fun, polished.fun))


def random_obstacle(shape: str, rng: np.random.Generator) -> ck.Obstacle:
    xyz = rng.uniform([-0.8, -0.8, 0.0], [0.8, 0.8, 1.0])
    rpy = rng.uniform(-np.pi, np.pi, 3)
    if shape == "box":
        return ck.Obstacle.box(rng.uniform(0.05, 0.3, 3), xyz, rpy)
    if shape == "sphere":
        return ck.Obstacle.sphere(rng.uniform(0.03, 0.2), xyz)
    make = ck.Obstacle.cylinder if shape == "cylinder" else ck.Obstacle.capsule
    return make(rng.uniform(0.03, 0.15), rng.uniform(0.1, 0.5), xyz, rpy)


def test_distances_against_independent_oracle(robot: ck.Robot, rng: np.random.Generator) -> None:
    checked = 0
    data = robot.model.createData()
    gdata = robot.collision_model.createData()
    for trial in range(8):  # two obstacles of each shape, every link against each
        shape = ("box", "sphere", "cylinder", "capsule")[trial % 4]
        obstacle = random_obstacle(shape, rng)
        world = ck.CollisionWorld(robot, [obstacle])
        q = random_configurations(robot, rng, 1)[0]
        clearance = world.clearance(q)
        pin.updateGeometryPlacements(robot.model, data, robot.collision_model, gdata, q)
        h_b = support(obstacle.geometry(), obstacle.placement)
        for g in robot.geometries:
            found = pair(clearance, g.name)
            if found.distance_m < 1e-3:
                continue
            placement = gdata.oMg[g.index]
            h_a = support(robot.collision_model.geometryObjects[g.index].geometry, placement)
            expected = separating_distance(h_a, h_b, found.point_on_obstacle - found.point_on_robot, rng)
            # coal's GJK stops at its default tolerance of 1e-6 (relative to the distance)
            assert found.distance_m == pytest.approx(expected, abs=2e-6), (shape, g.name)
            checked += 1
    assert checked >= 30


def test_reach_distance_bounds_every_pair_from_below(robot: ck.Robot, rng: np.random.Generator) -> None:
    obstacles = [random_obstacle(shape, rng) for shape in ("box", "sphere", "cylinder", "capsule", "box")]
    obstacles = [ck.Obstacle(**{**o.__dict__, "name": f"o{k}"}) for k, o in enumerate(obstacles)]
    world = ck.CollisionWorld(robot, obstacles)
    bound = pair_reach_distances(robot, world.obstacles, checked_pairs(robot, world.obstacles))
    assert np.sum(bound > 0.05) >= 3  # some pairs can be left out of the yes/no test
    configurations = random_configurations(robot, rng, 300)
    for q in configurations:
        actual = np.array([p.distance_m for p in world.clearance(q).pairs])
        assert np.all(actual >= bound - 1e-9)
    # and the culled yes/no check still agrees with the distances
    distances = world.clearance_batch(configurations).min_clearance_m
    for margin in (0.02, 0.1, 0.3):
        ambiguous = np.abs(distances - margin) < 1e-6
        np.testing.assert_array_equal(
            world.margin_violated(configurations, margin)[~ambiguous], (distances < margin)[~ambiguous]
        )


def test_reach_distance_of_the_turning_column_is_exact(robot: ck.Robot) -> None:
    # the 0.12 m square column turns about z: its corners sweep a cylinder of radius 0.06 sqrt(2);
    # a crate whose near face is 0.45 m from the axis, below the column's top, is that much closer
    crate = ck.Obstacle(shape="box", xyz=np.array([0.0, 0.6, 0.15]), size=np.array([0.3, 0.3, 0.3]), name="c")
    world = ck.CollisionWorld(robot, [crate])
    column = [p for p, (geometry, _, _) in enumerate(world.pairs) if geometry == "column"]
    reach = pair_reach_distances(robot, world.obstacles, checked_pairs(robot, world.obstacles))
    assert reach[column[0]] == pytest.approx(0.45 - 0.06 * np.sqrt(2), abs=1e-6)


def test_an_ordered_check_is_exact_up_to_the_first_failure(rng: np.random.Generator) -> None:
    """What an edge check needs: ordered, the answer up to the first failure, the rest failed."""
    from cpr_kin.model.packages import example_robot

    panda = ck.load_robot(example_robot("panda"))
    world = ck.CollisionWorld(
        panda,
        [
            ck.Obstacle.sphere(0.15, (0.45, 0.0, 0.4), name="ball"),
            ck.Obstacle.box(size=(0.2, 0.6, 0.02), xyz=(0.4, 0.0, 0.2), name="board"),
        ],
    )
    starts = rng.uniform(panda.limits.lower, panda.limits.upper, (60, panda.nq))
    ends = rng.uniform(panda.limits.lower, panda.limits.upper, (60, panda.nq))
    blocked_inside = 0
    for a, b in zip(starts, ends, strict=True):  # edges of 20 configurations, in order
        edge = a + np.linspace(0.0, 1.0, 20)[:, None] * (b - a)
        for full, ordered in (
            (world.margin_violated(edge, 0.05), world.margin_violated(edge, 0.05, ordered=True)),
            (~world.keeps_clearance(edge, 0.05, 0.02), ~world.keeps_clearance(edge, 0.05, 0.02, True)),
        ):
            first = int(np.argmax(full)) if full.any() else len(edge)
            np.testing.assert_array_equal(ordered[: first + 1], full[: first + 1])
            blocked_inside += int(0 < first < len(edge) - 1)
        violated = world.margin_violated(edge, 0.05)
        if violated.any():  # past the first violation: reported violated, untested
            assert world.margin_violated(edge, 0.05, ordered=True)[int(np.argmax(violated)) :].all()
    assert blocked_inside >= 10  # edges first blocked part of the way along, both checks


def test_keeps_clearance_is_both_margins_from_distances(rng: np.random.Generator) -> None:
    """The Panda among a ball: clear of it by the margin and of its own links by the self margin."""
    from cpr_kin.model.packages import example_robot

    panda = ck.load_robot(example_robot("panda"))
    world = ck.CollisionWorld(panda, [ck.Obstacle.sphere(0.15, (0.45, 0.0, 0.4), name="ball")])
    q = rng.uniform(panda.limits.lower, panda.limits.upper, (300, panda.nq))
    margin_m, self_margin_m = 0.05, 0.02
    assert world.self_collision
    obstacles = world.clearance_batch(q).min_clearance_m
    own = world.self_collision.distances(q)[0]
    expected = (obstacles >= margin_m) & (own >= self_margin_m)
    sure = (np.abs(obstacles - margin_m) > 1e-6) & (np.abs(own - self_margin_m) > 1e-6)
    assert 0 < expected.sum() < len(q)  # both outcomes drawn
    np.testing.assert_array_equal(world.keeps_clearance(q, margin_m, self_margin_m)[sure], expected[sure])


def test_a_world_of_something_else_is_named(robot: ck.Robot) -> None:
    # a list of names or dicts failed deep inside with an AttributeError
    with pytest.raises(ck.CprKinError, match=r"1 item\(s\) that are not cpr_kin.Obstacle \(a str\)"):
        ck.CollisionWorld(robot, [ck.Obstacle.sphere(0.1, (1.0, 0.0, 0.0)), "crate"])  # type: ignore[list-item]


def _views_and_fresh_distances(
    arm: str, rng: np.random.Generator, count: int
) -> tuple[np.ndarray, dict[str, ck.CollisionWorld], dict[str, tuple[np.ndarray, np.ndarray]]]:
    """An example arm among a box and a ball: ``count`` random configurations, the world and its
    hulls' view (the world's pools built first, as a plan's ends build them), and for each view a
    fresh world's obstacle and self distances there."""
    from cpr_kin.model.packages import example_robot

    robot = ck.load_robot(example_robot(arm))
    obstacles = [
        ck.Obstacle.box((0.3, 0.3, 0.3), (0.6, 0.0, 0.4)),
        ck.Obstacle.sphere(0.15, (-0.4, 0.3, 0.5)),
    ]
    fresh_world = functools.partial(ck.CollisionWorld, obstacles=obstacles, self_margin_m=0.01)
    q = rng.uniform(robot.limits.lower, robot.limits.upper, (count, robot.nq))
    world = fresh_world(robot)
    world.keeps_clearance(q[:5], 0.01, 0.01)
    views = {"meshes": world, "hulls": world.on_hulls()}
    truth = {
        name: (fresh.clearance_batch(q).min_clearance_m, fresh.self_collision.distances(q)[0])
        for name, fresh in (
            ("meshes", fresh_world(robot)),
            ("hulls", fresh_world(dataclasses.replace(robot, exact_meshes={}))),
        )
    }
    return q, views, truth


@pytest.mark.parametrize(  # every example arm but the SO-101 (dense meshes: 24 s); the Z1 where it failed
    ("arm", "seed"),
    [("panda", 0), ("ur3", 0), ("ur5", 0), ("ur10", 0), ("so100", 0), ("xarm7", 0), ("z1", 4)],
)
def test_a_world_and_its_hulls_view_keep_answering_as_distances_in_any_order(arm: str, seed: int) -> None:
    """Queries interleaved as a plan interleaves them: the world, then its hulls' view, then the world...

    Each at its margins (0 too), in batches or one at a time, ordered or not, must answer as
    a fresh world's distances do. Both share coal's pools, which keep what the last query set
    and coal's warm starts: the Panda's self test once answered at the margin the other had
    left, and at a margin of 0 coal's warm-started test proved two of the Z1's cylinders
    apart while 5 cm deep.
    """
    rng = np.random.default_rng(seed)
    q, views, truth = _views_and_fresh_distances(arm, rng, 400)
    wrong = []
    for step in range(300):
        name = str(rng.choice(list(views)))
        margin_m, self_margin_m = rng.choice([0.0, 0.001, 0.01, 0.03], size=2)
        rows = rng.choice(len(q), int(rng.choice([1, 7, 60])), replace=False)
        ordered = bool(rng.integers(2)) and len(rows) > 1
        kept = views[name].keeps_clearance(q[rows], margin_m, self_margin_m, ordered)
        obstacle_m, own_m = truth[name][0][rows], truth[name][1][rows]
        expected = (obstacle_m >= margin_m) & (own_m >= self_margin_m)
        sure = (np.abs(obstacle_m - margin_m) > 1e-6) & (np.abs(own_m - self_margin_m) > 1e-6)
        upto = int(np.argmax(~expected)) + 1 if ordered and not expected.all() else len(rows)
        if ((kept != expected) & sure)[:upto].any():
            wrong.append((step, name, float(margin_m), float(self_margin_m)))
    assert not wrong, f"(step, view, margin, self margin) answered unlike the distances: {wrong}"


def test_a_world_and_its_hulls_view_keep_measuring_as_a_fresh_world(rng: np.random.Generator) -> None:
    """Distances between margin tests, either view in turn: a fresh world's, within coal's error.

    With ``below_m``, a distance below it is exact on the hulls; on a link's exact mesh it may
    be its hull's, between the two (:meth:`cpr_kin.CollisionWorld.min_clearance_batch`).
    """
    from cpr_kin.collision.decisive import coal_error_m

    q, views, truth = _views_and_fresh_distances("ur5", rng, 200)
    for _ in range(150):
        name = str(rng.choice(list(views)))
        view, (obstacle_m, own_m) = views[name], truth[name]
        rows = rng.choice(len(q), int(rng.choice([1, 7, 40])), replace=False)
        view.keeps_clearance(q[rows], *rng.choice([0.0, 0.001, 0.01, 0.03], size=2))
        np.testing.assert_allclose(view.self_collision.distances(q[rows])[0], own_m[rows], rtol=0, atol=2e-6)
        np.testing.assert_allclose(view.min_clearance_batch(q[rows])[0], obstacle_m[rows], rtol=0, atol=2e-6)
        below_m = float(rng.choice([0.001, 0.01, 0.05]))
        near = view.min_clearance_batch(q[rows], below_m=below_m)[0]
        lower = truth["hulls"][0][rows] - coal_error_m(1.0)
        upper = obstacle_m[rows] + coal_error_m(1.0)
        below = obstacle_m[rows] < below_m - 1e-6
        assert np.all((near[below] >= lower[below]) & (near[below] <= upper[below]))
        assert np.all(near[obstacle_m[rows] > below_m + 1e-6] == np.inf)
