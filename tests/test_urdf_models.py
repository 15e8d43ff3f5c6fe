"""Collision meshes as convex shapes: the hull where coal holds it, else a capsule containing the mesh."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin

import cpr_kin as ck
from cpr_kin.description.urdf_models import convex_hulls
from cpr_kin.model.packages import example_robot_data_share

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
ROBOTS = SHARE / "example-robot-data" / "robots"


def mesh(vertices: np.ndarray, triangles: list[list[int]]) -> coal.BVHModelOBBRSS:
    model = coal.BVHModelOBBRSS()
    model.beginModel(len(triangles), len(vertices))
    model.addVertices(vertices)
    model.addTriangles(np.array(triangles))
    model.endModel()
    return model


def cone(rim: int) -> tuple[np.ndarray, list[list[int]]]:
    """A cone of ``rim`` base points and an apex 0.3 m above: the apex has ``rim`` neighbours."""
    angle = np.linspace(0.0, 2.0 * np.pi, rim, endpoint=False)
    vertices = np.vstack([np.c_[0.1 * np.cos(angle), 0.1 * np.sin(angle), np.zeros(rim)], [[0.0, 0.0, 0.3]]])
    sides = [[k, (k + 1) % rim, rim] for k in range(rim)]
    base = [[0, k, k + 1] for k in range(1, rim - 1)]
    return vertices, sides + base


def test_a_hull_coal_cannot_hold_becomes_a_capsule_containing_the_mesh() -> None:
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "spin")
    geometry_model = pin.GeometryModel()
    placement = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 1.1), np.array([0.2, -0.1, 0.4]))
    shapes = {"fan": cone(300), "plain": cone(40)}  # coal's convex shapes: at most 255 neighbours
    for name, (vertices, triangles) in shapes.items():
        geometry_model.addGeometryObject(
            pin.GeometryObject(name, joint, placement, mesh(vertices, triangles))
        )
    replaced = convex_hulls(geometry_model)
    assert [geometry_model.geometryObjects[s.geometry].name for s in replaced if not s.hull] == ["fan"]
    fan, plain = geometry_model.geometryObjects
    assert isinstance(plain.geometry, coal.Convex) and plain.placement.isApprox(placement)
    assert isinstance(fan.geometry, coal.Capsule)
    # every vertex of the mesh, placed in the joint's frame, within the capsule's radius of its axis
    vertices = shapes["fan"][0] @ placement.rotation.T + placement.translation
    half = fan.geometry.halfLength
    ends = np.array([fan.placement.act(np.array([0.0, 0.0, z])) for z in (-half, half)])
    axis = ends[1] - ends[0]
    t = np.clip((vertices - ends[0]) @ axis / (axis @ axis), 0.0, 1.0)
    distance = np.linalg.norm(vertices - (ends[0] + t[:, None] * axis), axis=1)
    assert distance.max() <= fan.geometry.radius + 1e-9
    assert fan.geometry.radius < 0.2 and half < 0.3  # about the cone's size, not a loose ball


def test_centauros_pelvis_is_its_hull_of_polygons() -> None:
    # Centauro's pelvis mesh has a hull vertex of 566 neighbouring triangles: loading ended
    # in coal's RuntimeError "Too many neighbors." (a traceback)
    import trimesh

    folder = ROBOTS / "centauro_description"
    robot = ck.load_robot(
        folder / "urdf" / "centauro.urdf", tcp="arm1_6", srdf=folder / "srdf" / "centauro.srdf"
    )
    assert robot.capsule_meshes == ()
    assert robot.joint_names == ("torso_yaw", *(f"j_arm1_{k}" for k in range(1, 7)))
    (pelvis,) = [
        g for g in robot.collision_model.geometryObjects if g.meshPath.endswith("pelvis_reduced.stl")
    ]
    assert isinstance(pelvis.geometry, coal.ConvexBase)
    hull = trimesh.load_mesh(pelvis.meshPath).convex_hull
    hull.apply_scale(np.asarray(pelvis.meshScale))
    # coal's distance from points outside to the hull is trimesh's, to 10 um (GJK's tolerance)
    rng = np.random.default_rng(0)
    points = rng.uniform(hull.bounds[0] - 0.1, hull.bounds[1] + 0.1, (200, 3))
    outside = points[hull.nearest.signed_distance(points) < -1e-3]
    request, result = coal.DistanceRequest(), coal.DistanceResult()
    for point in outside:
        result.clear()
        placed = coal.Transform3s(np.eye(3), point)
        distance = coal.distance(
            pelvis.geometry, coal.Transform3s(), coal.Sphere(1e-9), placed, request, result
        )
        assert abs(distance + hull.nearest.signed_distance(point[None])[0]) < 1e-5
    assert len(outside) > 100


def test_a_flat_mesh_becomes_a_capsule_containing_it_not_a_crash() -> None:
    # coal's Qhull crashed the process (a segmentation fault) on a mesh whose vertices span no volume
    model = pin.Model()
    joint = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "spin")
    geometry_model = pin.GeometryModel()
    plate = np.array([[0.0, 0.0, 0.0], [0.2, 0.0, 0.0], [0.2, 0.1, 0.0], [0.0, 0.1, 0.0]])
    rod = np.c_[np.linspace(0.0, 0.3, 5), np.zeros(5), np.zeros(5)]
    shapes = {"plate": (plate, [[0, 1, 2], [0, 2, 3]]), "rod": (rod, [[0, 1, 2], [2, 3, 4]])}
    for name, (vertices, triangles) in shapes.items():
        geometry_model.addGeometryObject(
            pin.GeometryObject(name, joint, pin.SE3.Identity(), mesh(vertices, triangles))
        )
    replaced = convex_hulls(geometry_model)
    assert [s.hull for s in replaced] == [False, False]
    for shape, (vertices, _) in zip(geometry_model.geometryObjects, shapes.values(), strict=True):
        assert isinstance(shape.geometry, coal.Capsule | coal.Sphere)
        half = getattr(shape.geometry, "halfLength", 0.0)
        ends = np.array([shape.placement.act(np.array([0.0, 0.0, z])) for z in (-half, half)])
        axis = ends[1] - ends[0]
        t = np.clip((vertices - ends[0]) @ axis / max(axis @ axis, 1e-300), 0.0, 1.0)
        assert (
            np.linalg.norm(vertices - (ends[0] + t[:, None] * axis), axis=1).max()
            <= shape.geometry.radius + 1e-9
        )
