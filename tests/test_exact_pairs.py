"""Pairs measured on exact meshes: analytic distances, trimesh's, and one answer from every query."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import trimesh

import cpr_kin as ck
import cpr_kin.shapes.exact_pairs as exact_pairs
from cpr_kin.model.packages import example_robot_data_share
from cpr_kin.shapes.exact_meshes import MeshSource, exact_meshes
from cpr_kin.shapes.exact_pairs import ExactPairs
from cpr_kin.shapes.mesh_pieces import Side, sides_apart
from tests.test_exact_meshes import bvh_of, l_shape

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
ROBOTS = SHARE / "example-robot-data" / "robots"


@pytest.fixture(autouse=True)
def own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CPR_FIREFLY_CACHE", str(tmp_path / "cache"))


@dataclasses.dataclass(frozen=True)
class LAndBall:
    """An L-shaped link (checked as its hull, its mesh kept) beside a ball, placed."""

    pairs: ExactPairs
    geometry_model: pin.GeometryModel
    geometry_data: pin.GeometryData
    hull_m: float

    @property
    def exact_m(self) -> float:
        return self.pairs.distance(self.geometry_data, 0, self.hull_m)


def l_and_ball(tmp_path: Path, centre: tuple[float, float, float], radius: float) -> LAndBall:
    mesh = l_shape()
    path = tmp_path / "l.stl"
    mesh.export(path)
    hull = bvh_of(mesh)
    hull.buildConvexHull(True, "Qt")
    geometry_model = pin.GeometryModel()
    geometry_model.addGeometryObject(pin.GeometryObject("link", 0, 0, pin.SE3.Identity(), hull.convex))
    at = pin.SE3(np.eye(3), np.array(centre))
    geometry_model.addGeometryObject(
        pin.GeometryObject("ball", 0, 0, at, ck.Obstacle.sphere(radius, centre).geometry())
    )
    geometry_model.addCollisionPair(pin.CollisionPair(0, 1))
    meshes = exact_meshes([MeshSource(0, bvh_of(mesh), pin.SE3.Identity(), str(path), (1.0, 1.0, 1.0))])
    model = pin.Model()
    geometry_data = geometry_model.createData()
    pin.updateGeometryPlacements(model, model.createData(), geometry_model, geometry_data, np.zeros(0))
    hull_m = float(pin.computeDistance(geometry_model, geometry_data, 0).min_distance)
    return LAndBall(ExactPairs(geometry_model, meshes), geometry_model, geometry_data, hull_m)


def test_a_ball_in_the_ls_notch_is_as_far_as_the_inner_faces(tmp_path: Path) -> None:
    # centre (0.7, 0.7): inside the hull, 0.2 m from both inner faces of the L
    found = l_and_ball(tmp_path, (0.7, 0.7, 0.05), 0.05)
    assert found.hull_m < 0.0
    assert found.exact_m == pytest.approx(0.15, abs=1e-6)
    assert found.pairs.refined.tolist() == [True] and 0.23 < found.pairs.excess_m[0] <= 0.25 + 1e-9


def test_a_ball_beyond_the_hull_is_measured_to_the_nearest_corner(tmp_path: Path) -> None:
    # centre (1.2, 1.2): nearest L points are the corners (1, 0.5) and (0.5, 1), sqrt(0.2^2 + 0.7^2) away
    found = l_and_ball(tmp_path, (1.2, 1.2, 0.05), 0.05)
    assert 0.0 < found.hull_m < found.exact_m
    assert found.exact_m == pytest.approx(np.hypot(0.2, 0.7) - 0.05, abs=1e-6)


def test_a_ball_held_inside_the_ls_body_penetrates(tmp_path: Path) -> None:
    # centre (0.25, 0.25) inside the long box, 0.05 m from its faces: no triangle meets the ball
    found = l_and_ball(tmp_path, (0.25, 0.25, 0.05), 0.01)
    assert found.exact_m == found.hull_m < 0.0


def test_the_margin_test_follows_the_mesh(tmp_path: Path) -> None:
    found = l_and_ball(tmp_path, (0.7, 0.7, 0.05), 0.05)  # 0.15 m from the mesh
    model = pin.Model()
    # the hulls 0.1 m deep, the sampled excess 0.247 m: the mesh is asked for margins up to 0.147 m
    for margin_m, expected in ((0.1, False), (0.14, False), (0.151, True), (0.3, True)):
        data = (model, model.createData(), found.geometry_model, found.geometry_data)
        violated = found.pairs.violated(*data, np.zeros((1, 0)), [0], np.array([margin_m]))
        assert violated[0] == expected
        # one margin for every pair asks the same
        assert found.pairs.violated(*data, np.zeros((1, 0)), [0], margin_m)[0] == expected


UR5 = ROBOTS / "ur_description" / "urdf" / "ur5_robot.urdf"
UR10 = ROBOTS / "ur_description" / "urdf" / "ur10_robot.urdf"


def test_a_urs_clearance_to_balls_is_trimeshs_distance_to_its_link_meshes() -> None:
    # each group's clearance is the smallest distance from a ball to a link mesh (trimesh's), and
    # every pair's distance at most its own (exact where it may be the closest)
    robot = ck.load_robot(UR5)
    assert {robot.geometries[g].link for g in robot.exact_meshes} >= {"upper_arm_link", "forearm_link"}
    rng = np.random.default_rng(5)
    centres = rng.uniform(-0.6, 0.6, (6, 3))
    balls = [ck.Obstacle.sphere(0.04, xyz, name=f"ball{k}") for k, xyz in enumerate(centres)]
    world = ck.CollisionWorld(robot, balls)
    data, geometry_data = robot.model.createData(), robot.collision_model.createData()
    files: dict[int, trimesh.Trimesh] = {
        g: trimesh.load(robot.collision_model.geometryObjects[g].meshPath, force="mesh")  # type: ignore[misc]
        for g in robot.exact_meshes
    }
    by_name = {g.name: g.index for g in robot.geometries}
    compared = 0
    for q in rng.uniform(robot.limits.lower, robot.limits.upper, (12, robot.nq)):
        pin.updateGeometryPlacements(robot.model, data, robot.collision_model, geometry_data, q)
        clearance = world.clearance(q)
        expected_min = dict.fromkeys(clearance.group_clearance_m, np.inf)
        for pair in clearance.pairs:
            g = by_name[pair.robot_geometry]
            expected = pair.distance_m  # a primitive: coal's is exact
            if g in files:
                scale = robot.collision_model.geometryObjects[g].meshScale
                mesh = trimesh.Trimesh(files[g].vertices * scale, files[g].faces)
                mesh.fix_normals()  # outward, for the sign of signed_distance
                mesh.apply_transform(geometry_data.oMg[g].homogeneous)
                centre = centres[int(pair.obstacle[4:])]
                by_rays = bool(mesh.contains(centre[None])[0])
                if by_rays != (trimesh.proximity.signed_distance(mesh, centre[None])[0] > 0.0):  # type: ignore[no-untyped-call]
                    expected_min[pair.group] = np.nan  # trimesh's two tests differ: not an oracle here
                    continue
                if by_rays:
                    expected = -np.inf
                else:
                    to_surface = trimesh.proximity.closest_point(mesh, centre[None])[1][0]  # type: ignore[no-untyped-call]
                    expected = to_surface - 0.04
                compared += 1
                assert pair.distance_m <= max(expected, 0.0) + 1e-6
            expected_min[pair.group] = min(expected_min[pair.group], expected)  # nan stays nan
        for group, found in clearance.group_clearance_m.items():
            if np.isnan(expected_min[group]):
                continue
            if expected_min[group] > 0.0:
                assert found == pytest.approx(expected_min[group], abs=1e-6)
            else:
                assert found <= 1e-6
    assert compared > 100


@pytest.mark.parametrize("urdf", [UR5, UR10])
def test_every_query_gives_one_answer_never_below_the_hulls(urdf: Path) -> None:
    robot = ck.load_robot(urdf)
    obstacles = [ck.Obstacle.box((0.2, 0.2, 0.2), (0.5, 0.0, 0.3)), ck.Obstacle.sphere(0.1, (0.2, 0.4, 0.5))]
    world = ck.CollisionWorld(robot, obstacles)
    on_hulls = ck.CollisionWorld(dataclasses.replace(robot, exact_meshes={}), obstacles)
    q = np.random.default_rng(6).uniform(robot.limits.lower, robot.limits.upper, (300, robot.nq))
    self_m, hull_self_m = world.self_collision.distances(q)[0], on_hulls.self_collision.distances(q)[0]
    clear_m, hull_clear_m = world.min_clearance_batch(q)[0], on_hulls.min_clearance_batch(q)[0]
    assert np.all(self_m >= hull_self_m - 1e-9) and np.all(clear_m >= hull_clear_m - 1e-9)
    assert np.sum(self_m > hull_self_m + 1e-3) > 30 and np.sum(clear_m > hull_clear_m + 1e-3) > 10
    for margin_m in (0.0, 0.01, 0.011, 0.05):  # 0.011: the default self margin and the search's step
        np.testing.assert_array_equal(world.self_collision.violated(q, margin_m), self_m < margin_m)
        np.testing.assert_array_equal(world.margin_violated(q, margin_m), clear_m < margin_m)
        one_by_one = [world.margin_violated(x[None], margin_m)[0] for x in q[:60]]
        np.testing.assert_array_equal(one_by_one, clear_m[:60] < margin_m)
    grouped = world.clearance_batch(q[:50]).clearance_m.min(axis=1)
    np.testing.assert_allclose(grouped, clear_m[:50], atol=1e-9)


def test_an_ordered_self_test_on_the_meshes_is_exact_up_to_its_first_violation() -> None:
    """Edges through the UR5's own links: the meshes decide up to the first violated configuration.

    Ordered, the answer equals the unordered one up to and including the first violation and
    is violated after it, on the exact meshes as on the hulls (where the meshes are skipped
    past it, the screen's later tiers too).
    """
    robot = ck.load_robot(UR5)
    world = ck.CollisionWorld(robot, [])
    rng = np.random.default_rng(8)
    starts = rng.uniform(robot.limits.lower, robot.limits.upper, (80, robot.nq))
    ends = rng.uniform(robot.limits.lower, robot.limits.upper, (80, robot.nq))
    blocked_inside = 0
    for a, b in zip(starts, ends, strict=True):
        edge = a + np.linspace(0.0, 1.0, 25)[:, None] * (b - a)
        for margin_m in (0.0, 0.011):
            full = world.self_collision.violated(edge, margin_m)
            ordered = world.self_collision.violated(edge, margin_m, ordered=True)
            first = int(np.argmax(full)) if full.any() else len(edge)
            np.testing.assert_array_equal(ordered[: first + 1], full[: first + 1])
            assert ordered[first:].all()
            blocked_inside += int(0 < first < len(edge) - 1 and not full[first:].all())
    assert blocked_inside >= 10  # edges first violated part of the way, and free again later


def test_the_convex_pieces_change_no_answer_of_the_margin_test(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    rng = np.random.default_rng(3)
    cases = [
        (tuple(rng.uniform((-0.2, -0.2, -0.1), (1.2, 1.2, 0.2)).tolist()), float(rng.uniform(0.01, 0.1)))
        for _ in range(40)
    ]
    placed = [l_and_ball(tmp_path, centre, radius) for centre, radius in cases]
    decided = []

    def counted(first: Side, second: Side, margin_m: float) -> float | None:
        found = sides_apart(first, second, margin_m)
        decided.append(found is not None)
        return found

    def answers() -> list[bool]:
        return [
            found.pairs.closer_than(found.geometry_data, 0, found.hull_m, margin_m)
            for found in placed
            for margin_m in (0.0, 0.01, 0.05, 0.12)
        ]

    monkeypatch.setattr(exact_pairs, "sides_apart", counted)
    with_pieces = answers()
    monkeypatch.setattr(exact_pairs, "sides_apart", lambda *_: None)  # the meshes decide every test
    assert answers() == with_pieces
    assert sum(decided) > 10  # where the hull comes within the margin, the pieces often answer
