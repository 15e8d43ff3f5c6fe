"""The robot filtered out of a cloud: the voxels kept and left out, against coal on every voxel; scenes."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml

import cpr_kin as ck
from cpr_kin.collision.self_filter import clear_of_robot
from cpr_kin.model.packages import example_robot
from cpr_kin.shapes.point_clouds import voxel_centres
from planning.cli import main

Q = np.array([0.4, 0.25, 0.3, 0.5, -0.4])
RESOLUTION_M = 0.02


def robot_points(robot: ck.Robot, q: np.ndarray, count: int, seed: int) -> np.ndarray:
    """Points inside the robot's collision shapes at ``q`` (drawn in each bounding box, kept by coal)."""
    import coal

    data, geometry_data = robot.model.createData(), robot.collision_model.createData()
    pin.updateGeometryPlacements(robot.model, data, robot.collision_model, geometry_data, q)
    rng = np.random.default_rng(seed)
    points = []
    for geometry in robot.geometries:
        shape = robot.collision_model.geometryObjects[geometry.index].geometry
        shape.computeLocalAABB()
        drawn = rng.uniform(shape.aabb_local.min_, shape.aabb_local.max_, (count, 3))
        dot = coal.Sphere(1e-9)
        inside = [
            p
            for p in drawn
            if coal.distance(
                shape,
                coal.Transform3s(),
                dot,
                coal.Transform3s(np.eye(3), p),
                coal.DistanceRequest(),
                coal.DistanceResult(),
            )
            < 0
        ]
        placement = geometry_data.oMg[geometry.index]
        points.append(np.asarray(inside) @ placement.rotation.T + placement.translation)
    return np.vstack(points)


def test_the_voxels_kept_are_those_coal_finds_beyond_the_padding() -> None:
    robot = ck.load_cpr()
    rng = np.random.default_rng(3)
    around = rng.uniform(-0.8, 0.8, (3000, 3)) + np.array([0.0, 0.0, 0.5])
    centres = voxel_centres(np.vstack([around, robot_points(robot, Q, 300, seed=4)]), RESOLUTION_M)
    cloud_in_world = pin.SE3(pin.rpy.rpyToMatrix(0.1, -0.2, 0.3), np.array([0.05, -0.02, 0.01]))
    padding_m = 0.03
    keep = clear_of_robot(robot, Q, centres, RESOLUTION_M, padding_m, cloud_in_world)
    # the oracle: coal on every voxel and every shape, no bounding box to skip a query
    import coal

    data, geometry_data = robot.model.createData(), robot.collision_model.createData()
    pin.updateGeometryPlacements(robot.model, data, robot.collision_model, geometry_data, Q)
    voxel = coal.Box(RESOLUTION_M, RESOLUTION_M, RESOLUTION_M)
    distance = np.array(
        [
            min(
                coal.distance(
                    robot.collision_model.geometryObjects[g.index].geometry,
                    coal.Transform3s(
                        geometry_data.oMg[g.index].rotation, geometry_data.oMg[g.index].translation
                    ),
                    voxel,
                    coal.Transform3s(cloud_in_world.rotation, cloud_in_world.act(centre)),
                    coal.DistanceRequest(),
                    coal.DistanceResult(),
                )
                for g in robot.geometries
            )
            for centre in centres
        ]
    )
    assert (~keep).sum() > 100 and keep.sum() > 1000  # both kinds are there
    np.testing.assert_array_equal(keep, distance > padding_m)


def test_a_negative_padding_is_refused() -> None:
    with pytest.raises(ck.CprKinError, match=r"padding = -0.01 m must be a finite distance >= 0"):
        clear_of_robot(ck.load_cpr(), Q, np.zeros((1, 3)), 0.01, -0.01)


def scene_with_cloud(tmp_path: Path, cloud: dict[str, object], start: dict[str, object]) -> Path:
    shelf = np.random.default_rng(5).uniform([0.4, 0.4, 0.0], [0.6, 0.6, 0.5], (2000, 3))
    np.save(tmp_path / "camera.npy", np.vstack([shelf, robot_points(ck.load_cpr(), Q, 300, seed=6)]))
    entry = {"name": "camera", "shape": "point_cloud", "file": "camera.npy", "resolution": 0.01, **cloud}
    document = {
        "start": start,
        "goal": {"q": [-1.0, 0.3, 0.35, 0.0, 0.0]},
        "safety_margin": 0.03,
        "obstacles": [entry],
    }
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(document))
    return path


@pytest.mark.slow
def test_a_cloud_with_the_robot_in_it_plans_once_the_robot_is_filtered_out(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    start = {"q": Q.tolist()}
    scene = scene_with_cloud(tmp_path, {}, start)
    assert main(["plan", str(scene), "--out", str(tmp_path / "raw")]) == 2
    assert "is inside the safety margin" in capsys.readouterr().err
    scene = scene_with_cloud(tmp_path, {"filter_robot": True}, start)
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    assert main(["check", str(scene), str(tmp_path / "out" / "trajectory.json")]) == 0


@pytest.mark.parametrize(
    ("cloud", "start", "message"),
    [
        (
            {"filter_robot": True},
            {"tcp": [0.5, 0.0, 0.3]},
            "obstacles[0]: filter_robot needs the start as joint values ('start: {q: [...]}'), where the "
            "robot stands in the cloud; the start is a tcp",
        ),
        ({"filter_padding": 0.02}, {"q": Q.tolist()}, "'filter_padding' goes with 'filter_robot: true'"),
        (
            {"filter_robot": True, "filter_padding": -0.1},
            {"q": Q.tolist()},
            "obstacles[0].filter_padding = -0.1",
        ),
    ],
)
def test_a_filter_that_cannot_work_is_refused_naming_it(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    cloud: dict[str, object],
    start: dict[str, object],
    message: str,
) -> None:
    scene = scene_with_cloud(tmp_path, cloud, start)
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert message in error and len(error.strip().splitlines()) == 1, error
    assert not (tmp_path / "out").exists()


def test_a_voxel_in_a_concave_links_hollow_stays_an_obstacle(monkeypatch: pytest.MonkeyPatch) -> None:
    # the UR5's forearm hull reaches ~40 mm beyond its mesh: voxels between them are not the robot's
    import coal
    import trimesh

    robot = ck.load_robot(example_robot("ur5"))
    q = np.array([0.3, -1.2, 1.4, -0.5, 0.8, 0.0])
    data, geometry_data = robot.model.createData(), robot.collision_model.createData()
    pin.updateGeometryPlacements(robot.model, data, robot.collision_model, geometry_data, q)
    meshes = []
    for index in robot.exact_meshes:
        obj = robot.collision_model.geometryObjects[index]
        loaded: trimesh.Trimesh = trimesh.load(obj.meshPath, force="mesh")  # type: ignore[assignment]
        mesh = trimesh.Trimesh(loaded.vertices * obj.meshScale, loaded.faces)
        mesh.fix_normals()  # outward, for the sign of signed_distance
        meshes.append(mesh.apply_transform(geometry_data.oMg[index].homogeneous))
    (forearm,) = [g.index for g in robot.geometries if g.link == "forearm_link"]
    assert forearm in robot.exact_meshes
    bounds = meshes[list(robot.exact_meshes).index(forearm)].bounds
    centres = voxel_centres(
        np.random.default_rng(8).uniform(bounds[0] - 0.05, bounds[1] + 0.05, (3000, 3)), 0.002
    )
    padding_m, half_diagonal = 0.01, 0.002 * np.sqrt(3.0) / 2.0
    keep = clear_of_robot(robot, q, centres, 0.002, padding_m)
    # the oracle: trimesh's distance from each centre to each exact mesh, inside where its ray
    # test (three times) and its signed distance agree (a centre where they differ is left out);
    # coal's to the other shapes (exact already); away from the band where the cube decides.
    # A ray through an edge is cast again in a random direction, from an unseeded generator
    # shared by all of trimesh: seeded here, each test with its own seed (one seed alone called
    # a centre inside the forearm outside, both ways, once in ten)
    to_robot = np.min([trimesh.proximity.closest_point(m, centres)[1] for m in meshes], axis=0)  # type: ignore[no-untyped-call]

    def seeded(seed: int) -> None:
        monkeypatch.setattr(trimesh.util, "random_generator", lambda *_: np.random.default_rng(seed))

    votes = []
    for seed in range(3):
        seeded(seed)
        votes.append([m.contains(centres) for m in meshes])
    by_rays = np.array(votes)
    seeded(3)
    by_sign = np.array([trimesh.proximity.signed_distance(m, centres) > 0.0 for m in meshes])  # type: ignore[no-untyped-call]
    known = np.all(by_rays == by_sign, axis=(0, 1))
    inside = np.any(by_rays[0], axis=0)
    for g in robot.geometries:
        if g.index not in robot.exact_meshes:
            at = geometry_data.oMg[g.index]
            shape, pose = (
                robot.collision_model.geometryObjects[g.index].geometry,
                coal.Transform3s(at.rotation, at.translation),
            )
            dot = coal.Sphere(1e-9)
            to_shape = [
                coal.distance(
                    shape,
                    pose,
                    dot,
                    coal.Transform3s(np.eye(3), c),
                    coal.DistanceRequest(),
                    coal.DistanceResult(),
                )
                for c in centres
            ]
            to_robot = np.minimum(to_robot, to_shape)
    robots = known & (inside | (to_robot < padding_m))
    clear = known & ~inside & (to_robot > padding_m + half_diagonal)
    assert not keep[robots].any() and keep[clear].all()
    on_hulls = clear_of_robot(dataclasses.replace(robot, exact_meshes={}), q, centres, 0.002, padding_m)
    assert (clear & ~on_hulls).sum() > 100  # what the hulls took for the robot's
