"""The margin tests GJK decides for a batch: coal's answers where it decides, coal asked for the rest."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh

import cpr_kin as ck
from cpr_kin.collision.hull_tests import HULL_HIT, HullTests
from cpr_kin.collision.obstacle_tests import ObstacleTests
from cpr_kin.shapes.convex_gjk import BOX, CONVEX, CYLINDER, SPHERE, UNSUPPORTED, UNSURE
from cpr_kin.shapes.exact_pairs import ExactPairs
from cpr_kin.shapes.gjk_shapes import MAX_VERTICES, GeometryShapes
from cpr_kin.shapes.mesh_geometry import convex_hull

from .conftest import random_configurations
from .test_collision import random_obstacle
from .test_exact_pairs import UR5


def world_of(robot: ck.Robot, tmp_path: Path, seed: int) -> ck.CollisionWorld:
    """``robot`` among two obstacles of each primitive and a concave mesh (a shape GJK leaves to coal)."""
    rng = np.random.default_rng(seed)
    obstacles = []
    for shape in ("box", "sphere", "cylinder", "capsule") * 2:  # about the robot, not over its base
        angle, radius = rng.uniform(-np.pi, np.pi), rng.uniform(0.4, 0.8)
        xyz = (radius * np.cos(angle), radius * np.sin(angle), rng.uniform(0.1, 0.9))
        obstacles.append(dataclasses.replace(random_obstacle(shape, rng), xyz=np.array(xyz)))
    mesh = tmp_path / "torus.stl"
    trimesh.creation.torus(0.25, 0.06).export(mesh)
    obstacles.append(ck.Obstacle.from_mesh(mesh, (0.7, -0.6, 0.3), convex=False))
    return ck.CollisionWorld(robot, [dataclasses.replace(o, name=f"o{k}") for k, o in enumerate(obstacles)])


def coal_alone(tests: ObstacleTests) -> ObstacleTests:
    """The same tests with coal asked for every pair (the oracle)."""
    alone = ObstacleTests(tests.model, tests.geometry_model, tests._exact)
    alone._hulls = None
    return alone


@pytest.mark.parametrize("ordered", [False, True])
def test_the_configurations_violated_are_coal_s(robot: ck.Robot, tmp_path: Path, ordered: bool) -> None:
    world = world_of(robot, tmp_path, 3)
    tests = ObstacleTests(robot.model, world.geometry_model)
    assert tests._hulls is not None
    rng = np.random.default_rng(4)
    pairs = np.arange(len(world.pairs))
    found = kept = 0
    for margin_m in (0.0, 0.02, 0.1):
        for _ in range(20):  # edges, as a sampling planner asks them
            a, b = random_configurations(robot, rng, 2)
            edge = a + np.linspace(0.0, 0.5, 25)[:, None] * (b - a)
            uncertain = rng.random((len(edge), len(pairs))) < 0.7
            violated = tests.violated(edge, uncertain, pairs, margin_m, ordered)
            np.testing.assert_array_equal(
                violated, coal_alone(tests).violated(edge, uncertain, pairs, margin_m, ordered)
            )
            found += int(violated.sum())
            kept += int(np.argmax(violated)) if violated.any() else len(edge)  # clear before the first
    assert found > 50 and kept > 50


def test_most_tests_are_decided_and_those_left_are_the_unsupported_shapes_or_near_the_margin(
    robot: ck.Robot, tmp_path: Path
) -> None:
    world = world_of(robot, tmp_path, 5)
    hulls = HullTests(robot.model, world.geometry_model)
    kinds = hulls.shapes.kinds
    assert set(kinds.tolist()) >= {BOX, SPHERE, CYLINDER, UNSUPPORTED}
    q = random_configurations(robot, np.random.default_rng(6), 200)
    margin_m, refined = 0.05, np.zeros(len(world.pairs), dtype=bool)
    left, unsupported, supported_tests = [], [], 0
    for pair, geometries in enumerate(
        world.geometry_model.collisionPairs
    ):  # one pair a call: each one tested
        uncertain = np.ones((len(q), 1), dtype=bool)
        verdicts = hulls.violated(q, uncertain, np.array([pair]), margin_m, refined, ordered=False)
        assert np.all(verdicts.states == UNSURE)
        if kinds[geometries.second] == UNSUPPORTED:
            unsupported.append(len(verdicts.rows))
            continue
        supported_tests += len(q)
        left += [(row, pair) for row in verdicts.rows]
    assert min(unsupported) == len(q)  # every test of a mesh obstacle goes to coal
    distances = np.array([world.clearance(q[row]).pairs[pair].distance_m for row, pair in left])
    assert np.all(np.abs(distances - margin_m) < 1e-4)  # a primitive's test only at the margin
    assert len(left) <= 0.01 * supported_tests


def test_a_hit_on_a_hull_with_a_mesh_is_left_to_the_mesh() -> None:
    robot = ck.load_robot(UR5)
    obstacles = [ck.Obstacle.box((0.2, 0.2, 0.2), (0.5, 0.0, 0.3)), ck.Obstacle.sphere(0.1, (0.2, 0.4, 0.5))]
    world = ck.CollisionWorld(robot, obstacles)
    exact = ExactPairs(world.geometry_model, robot.exact_meshes)
    hulls = HullTests(robot.model, world.geometry_model)
    assert CONVEX in hulls.shapes.kinds
    q = np.random.default_rng(7).uniform(robot.limits.lower, robot.limits.upper, (500, robot.nq))
    pairs = np.arange(len(world.pairs))
    uncertain = np.ones((len(q), len(pairs)), dtype=bool)
    verdicts = hulls.violated(q, uncertain, pairs, 0.02, exact.refined, ordered=False)
    on_meshes = verdicts.states == HULL_HIT
    assert on_meshes.any() and np.all(exact.refined[verdicts.pairs[on_meshes]])
    tests = ObstacleTests(robot.model, world.geometry_model, exact)
    np.testing.assert_array_equal(
        tests.violated(q, uncertain, pairs, 0.02), world.min_clearance_batch(q)[0] < 0.02
    )


def test_a_robot_with_a_joint_of_several_coordinates_is_left_to_coal() -> None:
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelSpherical(), pin.SE3.Identity(), "ball")
    geometry_model = pin.GeometryModel()
    geometry_model.addGeometryObject(
        pin.GeometryObject("link", joint, joint, pin.SE3.Identity(), coal.Sphere(0.1))
    )
    assert HullTests.of(model, geometry_model) is None
    assert GeometryShapes.of(geometry_model).kinds.tolist() == [SPHERE]


def test_a_hull_of_many_vertices_is_left_to_coal() -> None:
    points = np.random.default_rng(9).normal(size=(4 * MAX_VERTICES, 3))
    points /= np.linalg.norm(points, axis=1)[:, None]  # on a sphere: every point a vertex
    geometry_model = pin.GeometryModel()
    for hull in (convex_hull(points[: MAX_VERTICES // 2]), convex_hull(points)):
        geometry_model.addGeometryObject(pin.GeometryObject("hull", 0, 0, pin.SE3.Identity(), hull))
    shapes = GeometryShapes.of(geometry_model)
    assert shapes.kinds.tolist() == [CONVEX, UNSUPPORTED]
    assert shapes.first.tolist() == [0, MAX_VERTICES // 2, MAX_VERTICES // 2]
