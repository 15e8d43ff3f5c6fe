"""Pairs a few millimetres apart by design: found, held to contact only, and nothing else changed."""

from __future__ import annotations

import dataclasses

import coal
import numpy as np
import pinocchio as pin
import pytest
import trimesh

import cpr_kin as ck
from cpr_kin.bounds.close_pairs import CLOSE_LIMIT_M, close_pairs
from cpr_kin.collision.self_collision import SelfCollision
from cpr_kin.model.packages import example_robot_data_share
from planning.bench.arm_scenes import blocked_scene
from planning.io.report import report_markdown
from planning.io.scene_file import parse_scene
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem
from planning.pipeline.verification import verify_for_scene

from .conftest import turning_balls

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
ROBOTS = SHARE / "example-robot-data" / "robots"


def _turning_balls() -> tuple[pin.Model, pin.GeometryModel, dict[str, int]]:
    """Balls turning about a hub on the joint's axis: their gaps to the hub never change."""
    return turning_balls(
        {
            "hub": (False, 0.2, 0.0),
            "close": (True, 0.1, 0.306),  # 6 mm from the hub at every angle
            "touching": (True, 0.1, 0.29),  # 10 mm into it at every angle
            "far": (True, 0.1, 0.5),  # 200 mm from it
            "post": (False, 0.05, 0.462),  # 6 mm from the close ball at angle 0 only
        }
    )


def test_only_a_pair_apart_and_close_at_every_angle_is_found_with_its_largest_gap() -> None:
    model, geometry_model, ids = _turning_balls()
    names = ("hub", "close"), ("hub", "touching"), ("hub", "far"), ("post", "close")
    pairs = [(ids[a], ids[b]) for a, b in names]
    links = [f"link_of_{obj.name}" for obj in geometry_model.geometryObjects]
    (found,) = close_pairs(model, geometry_model, pairs, links)
    assert found.geometries == (ids["hub"], ids["close"])
    assert found.largest_m == pytest.approx(0.006, abs=1e-9)  # the balls' gap, analytic
    assert found.links == ("link_of_hub", "link_of_close")
    assert close_pairs(model, geometry_model, [], links) == ()
    assert CLOSE_LIMIT_M > 0.006


def test_a_pair_that_meets_in_places_and_stays_close_elsewhere_is_found_with_its_largest_gap() -> None:
    # a ball turning 0.302 m from the axis hugs a hub 10 mm off it: 8 mm into the hub at angle 0,
    # 12 mm from it at pi (analytic: |0.302 u(angle) - 0.01 x| - 0.3)
    model, geometry_model, ids = turning_balls({"hub": (False, 0.2, 0.01), "hugging": (True, 0.1, 0.302)})
    links = [f"link_of_{obj.name}" for obj in geometry_model.geometryObjects]
    (found,) = close_pairs(model, geometry_model, [(ids["hub"], ids["hugging"])], links)
    assert found.largest_m == pytest.approx(0.012, abs=1e-5)  # the sampled angles' largest gap
    assert found.held_to_contact(0.015) and not found.held_to_contact(0.01)


def _held_pair(allowance_m: float) -> tuple[SelfCollision, np.ndarray, np.ndarray]:
    """The close ball and the post (6 mm apart at angle 0, 0.618 m at pi), one allowance."""
    model, geometry_model, ids = _turning_balls()
    names = [obj.name for obj in geometry_model.geometryObjects]
    pairs = ((ids["post"], ids["close"]),)
    collision = SelfCollision(model, geometry_model, pairs, names, allowance_m=np.array([allowance_m]))
    angles = np.linspace(-np.pi, np.pi, 721)[:, None]
    centre = 0.306 * np.column_stack([np.cos(angles[:, 0]), np.sin(angles[:, 0])])
    exact = np.linalg.norm(centre - [0.462, 0.0], axis=1) - 0.15  # the balls' distance, analytic
    return collision, angles, exact


@pytest.mark.parametrize("allowance_m", [0.0, 0.01])
def test_an_allowance_adds_to_every_distance_bound_and_margin(allowance_m: float) -> None:
    collision, q, exact = _held_pair(allowance_m)
    counted = exact + allowance_m
    assert np.allclose(collision.distances(q)[0], counted, atol=1e-6)
    assert np.allclose(collision.pair_distances(q, 0), counted, atol=1e-6)
    assert np.all(collision.bounds(q)[:, 0] <= counted + 1e-6)
    assert np.all(collision.pair_bounds(q, 0) <= counted + 1e-6)
    for margin_m in (0.004, 0.012, 0.03, 0.1):
        # coal is asked for margin_m less the allowance, never below contact
        threshold = max(margin_m, allowance_m)
        decided = np.abs(counted - threshold) > 1e-6
        assert np.array_equal(collision.violated(q, margin_m)[decided], (counted < threshold)[decided])
        assert 0 < np.sum(counted < threshold) < len(q) or threshold < 0.006 + allowance_m


def test_a_pair_held_to_contact_only_is_still_checked_for_contact() -> None:
    collision, _, _ = _held_pair(0.01)
    # the post pushed 10 mm closer, 4 mm into the ball: held to contact, the margin still refuses it
    model, geometry_model, ids = _turning_balls()
    geometry_model.geometryObjects[ids["post"]].placement = pin.SE3(np.eye(3), np.array([0.452, 0.0, 0.0]))
    names = [obj.name for obj in geometry_model.geometryObjects]
    pairs = ((ids["post"], ids["close"]),)
    touching = SelfCollision(model, geometry_model, pairs, names, allowance_m=np.array([0.01]))
    at_zero = np.zeros((1, 1))
    assert touching.violated(at_zero, 0.01)[0] and not collision.violated(at_zero, 0.01)[0]
    assert touching.distances(at_zero)[0][0] == pytest.approx(-0.004 + 0.01, abs=1e-6)


def test_an_allowance_must_be_one_distance_per_pair() -> None:
    model, geometry_model, ids = _turning_balls()
    names = [obj.name for obj in geometry_model.geometryObjects]
    pairs = ((ids["post"], ids["close"]),)
    with pytest.raises(ck.CprKinError, match="allowance_m must be 1 distances >= 0"):
        SelfCollision(model, geometry_model, pairs, names, allowance_m=np.array([-0.01]))


TIAGO = {"urdf": str(ROBOTS / "tiago_description" / "robots" / "tiago.urdf"), "tcp": "arm_tool_link"}


def test_tiagos_wrist_pair_is_close_by_design_and_its_arm_plans() -> None:
    # Tiago's arm_5_link and arm_tool_link stay 4.3-6.6 mm apart (no SRDF): held to a 10 mm
    # self margin, every start was refused
    robot = ck.load_robot(TIAGO["urdf"], tcp=TIAGO["tcp"])
    close = {c.links: c.largest_m for c in robot.close_pairs}
    assert 0.004 < close[("arm_5_link", "arm_tool_link")] < 0.008
    q = np.random.default_rng(3).uniform(robot.limits.lower, robot.limits.upper, (300, robot.nq))
    strict = ck.CollisionWorld(robot, []).self_collision
    held = ck.CollisionWorld(robot, [], self_margin_m=0.01).self_collision
    assert strict.violated(q, 0.01).all()  # the pair alone refuses every configuration
    refused = held.violated(q, 0.01)
    assert 0.1 < refused.mean() < 0.9  # the arm folded into the torso still is
    counted = held.distances(q[:40])[0]
    assert np.array_equal(refused[:40], counted < 0.01)
    # on the hulls alone: the smallest of coal's distances over every pair, the close pair's
    # plus 10 mm, pair by pair; the exact meshes lie inside the hulls: never closer
    on_hulls = ck.CollisionWorld(dataclasses.replace(robot, exact_meshes={}), [], self_margin_m=0.01)
    hull_counted = on_hulls.self_collision.distances(q[:40])[0]
    assert np.all(counted >= hull_counted - 1e-9)
    geometry_model = held.geometry_model
    data, geometry_data = robot.model.createData(), geometry_model.createData()
    for x, found in zip(q[:40], hull_counted, strict=True):
        pin.computeDistances(robot.model, data, geometry_model, geometry_data, x)
        every = [r.min_distance for r in geometry_data.distanceResults] + held.allowance_m
        assert found == pytest.approx(min(every), abs=1e-9)
    scene = parse_scene(blocked_scene("tiago_700", TIAGO, robot, 700, self_clearance_m=0.015))
    result = plan(scene, robot)
    assert not verify_for_scene(build_problem(scene, robot), result.trajectory).problems  # `check`'s verdict
    assert "held to contact only (their largest sampled distance): arm_5_link / arm_tool_link (6.6 mm)" in (
        report_markdown(result)
    )


def test_a_world_refuses_a_self_margin_that_is_no_distance() -> None:
    robot = ck.load_cpr()
    for bad in (-0.01, float("nan"), float("inf")):
        with pytest.raises(ck.CprKinError, match="must be a finite distance >= 0"):
            ck.CollisionWorld(robot, [], self_margin_m=bad)


def test_arms_without_such_pairs_keep_every_margin() -> None:
    for urdf in ("panda_description/urdf/panda.urdf", "ur_description/urdf/ur5_robot.urdf"):
        robot = ck.load_robot(ROBOTS / urdf)
        world = ck.CollisionWorld(robot, [], self_margin_m=0.01)
        assert not world.self_collision.allowance_m.any()


FINGER = {
    "urdf": str(ROBOTS / "finger_edu_description" / "robots" / "finger_edu.urdf"),
    "tcp": "finger_tip_link",
}


def _meshes_apart_m(robot: ck.Robot, pair: tuple[int, int], q: np.ndarray) -> np.ndarray:
    """Coal's distance [m] of ``pair``'s link meshes as trimesh reads them, at each configuration."""
    objects = [robot.collision_model.geometryObjects[g] for g in pair]
    models = []
    for obj in objects:
        mesh: trimesh.Trimesh = trimesh.load(obj.meshPath, force="mesh")  # type: ignore[assignment]
        bvh = coal.BVHModelOBBRSS()
        bvh.beginModel(len(mesh.faces), len(mesh.vertices))
        bvh.addVertices(np.asarray(mesh.vertices * obj.meshScale, dtype=np.float64))
        bvh.addTriangles(np.asarray(mesh.faces, dtype=np.int64))
        bvh.endModel()
        models.append(bvh)
    data, request = robot.model.createData(), coal.DistanceRequest()
    apart = []
    for x in q:
        pin.forwardKinematics(robot.model, data, x)
        placed = [data.oMi[obj.parentJoint] * obj.placement for obj in objects]
        transforms = [coal.Transform3s(at.rotation, at.translation) for at in placed]
        result = coal.DistanceResult()
        coal.distance(models[0], transforms[0], models[1], transforms[1], request, result)
        apart.append(result.min_distance)
    return np.array(apart)


def test_a_finger_whose_middle_link_meets_its_base_in_places_is_held_to_contact_and_plans() -> None:
    # finger_edu's middle link stays 3-4 mm from the base's front housing wherever it does not
    # swing into it: held to a 10 mm self margin, every configuration was refused
    robot = ck.load_robot(FINGER["urdf"], tcp=FINGER["tcp"])
    (close,) = [c for c in robot.close_pairs if c.held_to_contact(0.01)]
    assert close.links == ("finger_base_link", "finger_middle_link")
    assert 0.003 < close.largest_m < 0.005
    q = np.random.default_rng(5).uniform(robot.limits.lower, robot.limits.upper, (200, robot.nq))
    held = ck.CollisionWorld(robot, [], self_margin_m=0.01).self_collision
    refused = held.violated(q, 0.01)
    meshes_m = _meshes_apart_m(robot, close.geometries, q)
    assert 0.05 < np.mean(meshes_m <= 0.0) < 0.5  # the meshes meet in places (oracle: trimesh + coal)
    assert refused[meshes_m <= 0.0].all()  # held to contact: meeting is refused still
    assert np.mean(~refused) > 0.3 and np.all(meshes_m[~refused] > 0.0)
    scene = parse_scene(
        {
            "name": "finger",
            "robot": FINGER,
            "start": {"q": [0.0, -0.5, 1.0]},
            "goal": {"q": [0.6, 0.5, -1.2]},
            "obstacles": [],
        }
    )
    result = plan(scene, robot)
    assert not verify_for_scene(build_problem(scene, robot), result.trajectory).problems  # `check`'s verdict
    assert "finger_base_link / finger_middle_link" in report_markdown(result)
