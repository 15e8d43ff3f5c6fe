from __future__ import annotations

from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh

import cpr_kin as ck
from cpr_kin.bounds.bound_kernels import CAPSULE
from cpr_kin.bounds.box_distance import segment_box_distance
from cpr_kin.bounds.obstacle_bounds import obstacle_arrays, obstacle_bound
from cpr_kin.bounds.pair_bounds import PairBounds, bounding_capsule
from cpr_kin.collision.robot_reach import robot_capsules

from .conftest import random_configurations
from .test_collision import random_obstacle

SHAPES = ("box", "sphere", "cylinder", "capsule")


def all_pairs(robot: ck.Robot, obstacles: list[ck.Obstacle]) -> list[tuple[int, int]]:
    return [(g.index, k) for g in robot.geometries for k in range(len(obstacles))]


def coal_distances(robot: ck.Robot, world: ck.CollisionWorld, q: np.ndarray) -> np.ndarray:
    return np.array([[p.distance_m for p in world.clearance(qk).pairs] for qk in q])


@pytest.mark.parametrize(
    ("geometry", "inside"),
    [
        (coal.Box(0.7, 0.05, 0.05), [[0.35, 0.025, 0.025], [-0.35, -0.025, 0.025], [0.0, 0.0, -0.025]]),
        (coal.Cylinder(0.035, 0.08), [[0.035, 0.0, 0.04], [0.0, -0.035, -0.04]]),
        (coal.Capsule(0.02, 0.3), [[0.0, 0.0, 0.17], [0.02, 0.0, -0.15]]),
        (coal.Sphere(0.1), [[0.1, 0.0, 0.0], [0.0, 0.0, -0.1]]),
    ],
)
def test_bounding_capsule_contains_the_shape(geometry: object, inside: list[list[float]]) -> None:
    ends, radius = bounding_capsule(geometry)
    for point in np.array(inside):
        d = ends[1] - ends[0]
        t = np.clip((point - ends[0]) @ d / max(d @ d, 1e-300), 0.0, 1.0)
        assert np.linalg.norm(point - ends[0] - t * d) <= radius + 1e-12


def test_bounds_never_exceed_coal_distances(robot: ck.Robot, rng: np.random.Generator) -> None:
    obstacles = [random_obstacle(shape, rng) for shape in SHAPES for _ in range(3)]
    obstacles = [ck.Obstacle(**{**o.__dict__, "name": f"o{k}"}) for k, o in enumerate(obstacles)]
    world = ck.CollisionWorld(robot, obstacles)
    configurations = random_configurations(robot, rng, 150)
    bounds = PairBounds(robot.model, robot.collision_model, obstacles, all_pairs(robot, obstacles))(
        configurations
    )
    exact = coal_distances(robot, world, configurations)
    positive = bounds > 0.0
    # a positive bound is a distance lower bound, up to coal's GJK tolerance (about 1e-6)
    assert np.all(bounds[positive] <= exact[positive] + 2e-6)
    overlapping = exact < 0.0
    assert overlapping.any() and np.all(bounds[overlapping] <= 0.0)
    # and they are useful: most pairs that keep 10 cm are certified to keep 5 cm
    far = exact > 0.1
    assert np.mean(bounds[far] > 0.05) > 0.8


def test_bounds_on_kept_capsules_and_shared_obstacles_are_those_built_afresh(
    robot: ck.Robot, rng: np.random.Generator
) -> None:
    """A world's pair sets share the robot's capsules and chain and the obstacles' arrays: the same bits."""
    obstacles = [random_obstacle(shape, rng) for shape in SHAPES for _ in range(2)]
    obstacles = [ck.Obstacle(**{**o.__dict__, "name": f"o{k}"}) for k, o in enumerate(obstacles)]
    pairs = all_pairs(robot, obstacles)
    configurations = random_configurations(robot, rng, 100)
    chain, known = robot_capsules(robot)
    shapes = obstacle_arrays(obstacles)
    model, collision = robot.model, robot.collision_model
    for subset in (pairs[1::3], pairs[::2], pairs):
        fresh = PairBounds(model, collision, obstacles, subset)
        kept = PairBounds(model, collision, obstacles, subset, chain=chain, known=known, shapes=shapes)
        np.testing.assert_array_equal(kept(configurations), fresh(configurations))
        for threshold in (0.0, 0.05):
            np.testing.assert_array_equal(
                kept.pairs_below(configurations, threshold), fresh.pairs_below(configurations, threshold)
            )
    assert set(known) == {g for g, _ in pairs}  # each capsule fitted once, then kept with the robot
    assert robot_capsules(robot).known is known


def test_any_below_is_sound_and_at_most_the_bounds_answer(robot: ck.Robot, rng: np.random.Generator) -> None:
    obstacles = [random_obstacle(shape, rng) for shape in SHAPES]
    obstacles = [ck.Obstacle(**{**o.__dict__, "name": f"o{k}"}) for k, o in enumerate(obstacles)]
    bounds = PairBounds(robot.model, robot.collision_model, obstacles, all_pairs(robot, obstacles))
    configurations = random_configurations(robot, rng, 300)
    exact = coal_distances(robot, ck.CollisionWorld(robot, obstacles), configurations).min(axis=1)
    per_pair = bounds(configurations)
    for threshold in (0.0, 0.05, 0.1):
        uncertain = bounds.any_below(configurations, threshold)
        # sound: every configuration within the threshold is flagged (up to coal's tolerance)
        assert np.all(uncertain[exact <= threshold - 2e-6])
        # the spheres' test only ever clears more: never flags what the bounds clear
        assert not np.any(uncertain & ~(per_pair <= threshold).any(axis=1))
        assert uncertain.any() and not uncertain.all()


def test_pairs_below_is_any_below_pair_by_pair(robot: ck.Robot, rng: np.random.Generator) -> None:
    obstacles = [random_obstacle(shape, rng) for shape in SHAPES]
    obstacles = [ck.Obstacle(**{**o.__dict__, "name": f"o{k}"}) for k, o in enumerate(obstacles)]
    pairs = all_pairs(robot, obstacles)
    bounds = PairBounds(robot.model, robot.collision_model, obstacles, pairs)
    configurations = random_configurations(robot, rng, 300)
    exact = coal_distances(robot, ck.CollisionWorld(robot, obstacles), configurations)
    per_pair = bounds(configurations)
    for threshold in (0.0, 0.05, 0.1):
        flagged = bounds.pairs_below(configurations, threshold)
        assert flagged.shape == (len(configurations), len(pairs))
        np.testing.assert_array_equal(flagged.any(axis=1), bounds.any_below(configurations, threshold))
        assert np.all(flagged[exact <= threshold - 2e-6])  # sound pair by pair (coal's tolerance)
        assert not np.any(flagged & ~(per_pair <= threshold))  # the spheres only ever clear more
        for p in range(0, len(pairs), 7):  # each pair's answer is its own any_below
            own = PairBounds(robot.model, robot.collision_model, obstacles, [pairs[p]])
            np.testing.assert_array_equal(flagged[:, p], own.any_below(configurations, threshold))
    assert (flagged.sum(axis=1) >= 2).any() and (flagged.sum(axis=1) < flagged.shape[1]).all()


def test_mesh_obstacle_is_bounded_by_its_bounding_box(
    robot: ck.Robot, rng: np.random.Generator, tmp_path: Path
) -> None:
    path = tmp_path / "tetra.stl"
    trimesh.Trimesh(
        vertices=[[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [0.0, 0.2, 0.0], [0.1, 0.1, 0.25]],
        faces=[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    ).export(path)
    mesh = ck.Obstacle.from_mesh(path, xyz=(0.2, 0.45, 0.3), rpy=(0.3, -0.2, 0.5), name="tetra")
    world = ck.CollisionWorld(robot, [mesh])
    configurations = random_configurations(robot, rng, 300)
    bounds = PairBounds(robot.model, robot.collision_model, [mesh], all_pairs(robot, [mesh]))(configurations)
    exact = coal_distances(robot, world, configurations)
    positive = bounds > 0.0
    assert positive.mean() > 0.5
    assert np.all(bounds[positive] <= exact[positive] + 2e-6)


def test_a_round_mesh_obstacle_is_bounded_by_its_fitted_capsule(
    robot: ck.Robot, rng: np.random.Generator, tmp_path: Path
) -> None:
    """A tilted rod (radius 0.03 m, 0.5 m long): its box's half diagonal across would be 0.2 m."""
    path = tmp_path / "rod.stl"
    rod = trimesh.creation.cylinder(radius=0.03, height=0.5, sections=32)
    rod.apply_transform(trimesh.transformations.rotation_matrix(0.8, [1.0, 1.0, 0.0]))  # type: ignore[no-untyped-call]
    rod.export(path)
    mesh = ck.Obstacle.from_mesh(path, xyz=(0.3, 0.4, 0.3), rpy=(0.1, 0.2, 0.3), name="rod")
    bound = obstacle_bound(mesh)
    kind, radius, half = bound.kind, bound.radius, bound.half
    assert (
        kind == CAPSULE
        and radius == pytest.approx(0.03, abs=1e-6)
        and half[2] == pytest.approx(0.25, abs=1e-6)
    )
    world = ck.CollisionWorld(robot, [mesh])
    configurations = random_configurations(robot, rng, 300)
    bounds = PairBounds(robot.model, robot.collision_model, [mesh], all_pairs(robot, [mesh]))(configurations)
    exact = coal_distances(robot, world, configurations)
    positive = bounds > 0.0
    assert positive.mean() > 0.5
    assert np.all(bounds[positive] <= exact[positive] + 2e-6)


def test_the_box_bound_is_the_segment_s_exact_distance() -> None:
    """Oracle: coal's distance from a capsule of radius 1 cm to a box, plus that radius, on
    random segments about boxes (flat boards, bars, cubes), beside, over and through them."""
    rng = np.random.default_rng(7)
    request, checked = coal.DistanceRequest(), 0
    for _ in range(600):
        half = rng.uniform(0.002, 0.4, 3)
        a, b = rng.uniform(-0.6, 0.6, (2, 3))
        if rng.random() < 0.3:  # parallel to a face (one zero step) or to an axis (two)
            still = rng.choice(3, size=rng.integers(1, 3), replace=False)
            b[still] = a[still]
        bound = segment_box_distance(*a, *(b - a), *half)
        along = b - a
        length = float(np.linalg.norm(along))
        if length < 1e-6:
            continue
        rotation = pin.Quaternion.FromTwoVectors(np.array([0.0, 0.0, 1.0]), along / length).matrix()
        segment = coal.Transform3s(rotation, (a + b) / 2)
        result = coal.DistanceResult()
        box = (coal.Box(*(2 * half)), coal.Transform3s())
        coal.distance(coal.Capsule(0.01, length), segment, *box, request, result)
        exact = result.min_distance + 0.01  # while the segment stays outside the box
        if exact < 1e-5:  # it touches or enters the box: coal's depth is not the segment's
            assert bound <= 1e-5 + 2e-6
            continue
        assert bound == pytest.approx(exact, abs=2e-6)
        checked += 1
    assert checked > 400
    # and it is the minimum over the segment's points (an independent check, no coal)
    for _ in range(200):
        half = rng.uniform(0.01, 0.3, 3)
        a, b = rng.uniform(-0.5, 0.5, (2, 3))
        points = a + np.linspace(0.0, 1.0, 20001)[:, None] * (b - a)
        sampled = np.linalg.norm(np.maximum(np.abs(points) - half, 0.0), axis=1).min()
        bound = segment_box_distance(*a, *(b - a), *half)
        assert sampled - 1e-4 <= bound <= sampled + 1e-12


def test_sphere_bound_is_exact_beside_a_cylinder_side(robot: ck.Robot) -> None:
    # the wrist is a horizontal cylinder (radius 0.035 m), bounded by a capsule of the same
    # radius and axis: straight above its centre, both are 0.3 - 0.035 - 0.05 m from a ball
    q = np.array([0.0, 0.3, 0.2, 0.0, 0.0])
    wrist = next(g for g in robot.geometries if g.name == "wrist")
    gdata = robot.collision_model.createData()
    pin.forwardKinematics(robot.model, robot.data, q)
    pin.updateGeometryPlacements(robot.model, robot.data, robot.collision_model, gdata)
    placement = gdata.oMg[wrist.index]
    assert abs(placement.rotation[2, 2]) < 1e-12  # the cylinder's axis is horizontal
    ball = ck.Obstacle.sphere(0.05, placement.translation + np.array([0.0, 0.0, 0.3]), name="ball")
    bound = PairBounds(robot.model, robot.collision_model, [ball], [(wrist.index, 0)])(q[None])[0, 0]
    exact = coal_distances(robot, ck.CollisionWorld(robot, [ball]), q[None])[0, wrist.index]
    assert exact == pytest.approx(0.3 - 0.035 - 0.05, abs=1e-9)
    assert bound == pytest.approx(exact, abs=1e-9)


def test_margin_check_with_bounds_agrees_with_distances_for_every_shape(
    robot: ck.Robot, rng: np.random.Generator
) -> None:
    for shape in SHAPES:
        obstacles = [
            ck.Obstacle(**{**random_obstacle(shape, rng).__dict__, "name": f"o{k}"}) for k in range(3)
        ]
        world = ck.CollisionWorld(robot, obstacles)
        configurations = random_configurations(robot, rng, 400)
        distances = world.clearance_batch(configurations).min_clearance_m
        for margin in (0.0, 0.05, 0.2):
            violated = world.margin_violated(configurations, margin)
            ambiguous = np.abs(distances - margin) < 1e-6
            np.testing.assert_array_equal(violated[~ambiguous], (distances < margin)[~ambiguous])


def test_flat_boxes_are_flagged_exactly_where_their_bounds_are_below(
    robot: ck.Robot, rng: np.random.Generator
) -> None:
    # shelves and table tops, turned: their bounding spheres let most capsules in, and the
    # capsule centre's gap to the box decides first; it may only skip what the bound clears
    obstacles = [
        ck.Obstacle.box(
            [rng.uniform(0.4, 1.2), rng.uniform(0.3, 0.8), rng.uniform(0.01, 0.04)],
            rng.uniform([-0.6, -0.6, 0.0], [0.6, 0.6, 0.9]),
            rng.uniform(-np.pi, np.pi, 3),
            name=f"shelf{k}",
        )
        for k in range(6)
    ]
    pairs = all_pairs(robot, obstacles)
    bounds = PairBounds(robot.model, robot.collision_model, obstacles, pairs)
    configurations = random_configurations(robot, rng, 400)
    per_pair = bounds(configurations)
    for threshold in (0.0, 0.02, 0.1):
        flagged = bounds.pairs_below(configurations, threshold)
        np.testing.assert_array_equal(flagged, per_pair <= threshold)
        assert flagged.any() and not flagged.all()


def test_world_extents_hold_each_obstacle_as_coal_bounds_it(rng: np.random.Generator) -> None:
    # the margin test's first test: a box in the world's axes about the bound's centre holds
    # the obstacle (coal's own axis-aligned box of it), and is tight for a box
    for shape in (*SHAPES, *SHAPES):
        obstacle = random_obstacle(shape, rng)
        bound = obstacle_bound(obstacle)
        centre, extent = bound.centre, bound.world_extent
        placed = coal.CollisionObject(obstacle.geometry(), coal.Transform3s(obstacle.placement))
        placed.computeAABB()
        low, high = np.asarray(placed.getAABB().min_), np.asarray(placed.getAABB().max_)
        assert np.all(centre - extent <= low + 1e-9) and np.all(high <= centre + extent + 1e-9)
        if shape == "box":
            np.testing.assert_allclose(centre - extent, low, atol=1e-9)
            np.testing.assert_allclose(centre + extent, high, atol=1e-9)
