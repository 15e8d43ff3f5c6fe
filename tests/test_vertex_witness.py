"""A mesh vertex within a margin of a primitive: coal's distances as the oracle, and never a wrong proof."""

from __future__ import annotations

import itertools
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot_data_share
from cpr_kin.shapes.exact_pairs import ExactPairs
from cpr_kin.shapes.vertex_witness import VertexWitness, primitive_of, vertex_groups

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
UR5 = SHARE / "example-robot-data" / "robots" / "ur_description" / "urdf" / "ur5_robot.urdf"

PRIMITIVES = [coal.Sphere(0.1), coal.Box(0.2, 0.4, 0.1), coal.Cylinder(0.1, 0.4), coal.Capsule(0.05, 0.3)]


@pytest.fixture(autouse=True)
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))


def coal_distance(point: np.ndarray, shape: Any, at: pin.SE3) -> float:
    """coal's signed distance [m] from ``point`` (a ball of no radius) to ``shape`` placed at ``at``."""
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    request.enable_signed_distance = True
    dot, at_dot = coal.Sphere(1e-12), coal.Transform3s(np.eye(3), point)
    coal.distance(dot, at_dot, shape, coal.Transform3s(at.rotation, at.translation), request, result)
    return float(result.min_distance)


@pytest.mark.parametrize("shape", PRIMITIVES, ids=lambda s: type(s).__name__)
def test_a_vertex_is_within_a_margin_exactly_where_coal_measures_it_so(shape: Any) -> None:
    rng = np.random.default_rng(7)
    primitive = primitive_of(shape)
    assert primitive is not None
    for _ in range(200):
        at = pin.SE3(pin.exp3(rng.normal(size=3)), rng.uniform(-0.2, 0.2, 3))  # the shape in the world
        point = rng.uniform(-0.5, 0.5, 3)  # a vertex, in the world
        distance = coal_distance(point, shape, at)
        for margin, expected in ((distance + 1e-6, True), (distance - 1e-6, False)):
            found = vertex_groups(point[None]).within(at.inverse(), primitive, margin)
            assert found == expected, (distance, margin)


def test_other_shapes_are_no_primitive() -> None:
    assert primitive_of(coal.Cone(0.1, 0.2)) is None
    assert primitive_of(coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0)) is None


def test_the_groups_hold_each_corner_once_within_their_balls() -> None:
    corners = np.random.default_rng(2).uniform(-0.3, 0.3, (500, 3))
    groups = vertex_groups(corners)
    assert sorted(map(tuple, groups.vertices)) == sorted(map(tuple, corners))
    assert groups.starts[0] == 0 and groups.starts[-1] == len(corners) and np.all(np.diff(groups.starts) > 0)
    assert len(groups.radii) <= 4**3
    for g, (a, b) in enumerate(itertools.pairwise(groups.starts)):
        reach = np.linalg.norm(groups.vertices[a:b] - groups.centres[g], axis=1).max()
        assert reach <= groups.radii[g] + 1e-15


def test_the_nearest_vertex_decides_beside_a_far_group() -> None:
    near = np.array([[0.0, 0.0, 0.0], [0.01, 0.0, 0.0], [0.0, 0.01, 0.0]])
    far = near + np.array([1.0, 1.0, 1.0])
    groups = vertex_groups(np.concatenate([near, far]))
    ball = primitive_of(coal.Sphere(0.05))
    assert ball is not None
    place = pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.2]))  # the near triangle 0.15 m from the ball
    assert not groups.within(place, ball, 0.14) and groups.within(place, ball, 0.16)


def test_a_proof_is_a_hit_on_the_mesh_and_the_margin_test_answers_as_without_it() -> None:
    # the UR5's exact meshes beside primitives near its links, at random configurations: every
    # proof is a distance on the mesh below the margin (coal's), and closer_than's answer is the
    # one coal's test alone gives
    robot = ck.load_robot(UR5)
    rng = np.random.default_rng(3)
    obstacles = [
        ck.Obstacle.box((0.1, 0.3, 0.2), tuple(rng.uniform(-0.4, 0.4, 3)), name="box"),
        ck.Obstacle.cylinder(0.04, 0.3, tuple(rng.uniform(-0.4, 0.4, 3)), name="can"),
        ck.Obstacle.sphere(0.08, tuple(rng.uniform(-0.4, 0.4, 3)), name="ball"),
    ]
    world = ck.CollisionWorld(robot, obstacles)
    geometry_model = world.geometry_model
    pairs = ExactPairs(geometry_model, robot.exact_meshes)
    shapes = [obj.geometry for obj in geometry_model.geometryObjects]
    witness = VertexWitness(shapes, robot.exact_meshes)
    plain = ExactPairs(geometry_model, robot.exact_meshes)
    plain._witness = VertexWitness(shapes, {})  # proves nothing: coal alone
    data, geometry_data = robot.model.createData(), geometry_model.createData()
    proofs = 0
    for q in rng.uniform(robot.limits.lower, robot.limits.upper, (150, robot.nq)):
        pin.updateGeometryPlacements(robot.model, data, geometry_model, geometry_data, q)
        for index, cp in enumerate(geometry_model.collisionPairs):
            a, b = int(cp.first), int(cp.second)
            if not pairs.refined[index] or (a in robot.exact_meshes) == (b in robot.exact_meshes):
                continue
            mesh_side = a if a in robot.exact_meshes else b
            mesh = robot.exact_meshes[mesh_side]
            at_a = geometry_data.oMg[a] * (mesh.mesh_in_shape if a == mesh_side else pin.SE3.Identity())
            at_b = geometry_data.oMg[b] * (mesh.mesh_in_shape if b == mesh_side else pin.SE3.Identity())
            hull = float(pin.computeDistance(geometry_model, geometry_data, index).min_distance)
            on_mesh = pairs.distance(geometry_data, index, hull)  # the hulls' where the meshes meet
            for margin in (0.0, 0.01, 0.05):
                if witness.proves(a, at_a, b, at_b, margin):
                    proofs += 1
                    assert on_mesh < margin + 1e-6
                if abs(on_mesh - margin) > 1e-5:
                    assert pairs.closer_than(geometry_data, index, hull, margin) == plain.closer_than(
                        geometry_data, index, hull, margin
                    )
    assert proofs > 50
