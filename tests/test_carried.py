"""A payload's collision shape, carried by the robot: clearance, self pairs, the scene and the viewer."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import cpr_kin as ck
from cpr_kin.certified.motion import motion_radii
from cpr_kin.kinematics.carried import PAYLOAD_GEOMETRY
from planning.cli import main
from planning.io.scene_file import parse_scene, scene_document

BOX = ck.Obstacle.box([0.08, 0.08, 0.2], [0.0, 0.0, -0.1], name="part")  # hangs 0.2 m below the tool
Q = np.array([0.3, 0.4, 0.3, 0.0, 0.0])


@pytest.fixture(scope="module")
def robot() -> ck.Robot:
    return ck.load_cpr()


@pytest.fixture(scope="module")
def carried(robot: ck.Robot) -> ck.Robot:
    return ck.carrying(robot, ck.Payload(1.0, shape=BOX))


def test_the_shape_is_one_more_effector_geometry_paired_with_the_links_it_can_meet(
    robot: ck.Robot, carried: ck.Robot
) -> None:
    added = carried.geometries[-1]
    assert added.name == PAYLOAD_GEOMETRY and added.group == "effector" and added.link == robot.tcp_frame
    assert carried.geometries[:-1] == robot.geometries
    partners = {carried.geometries[a].link for a, b in carried.self_pairs if b == added.index}
    assert partners == {
        "base_link",
        "column_link",
        "carriage_link",
        "arm_link",
    }  # not the wrist, not the tool
    assert np.all(motion_radii(carried) >= motion_radii(robot))
    assert carried.visual_model.ngeoms == robot.visual_model.ngeoms + 1
    assert ck.carrying(robot, ck.Payload(1.0)) is robot  # no shape: the same robot


def test_the_shapes_clearance_is_the_distance_below_the_tool(carried: ck.Robot) -> None:
    tcp = ck.frame_positions(carried, Q)
    # a sphere of radius 0.05 straight below the tool: the box's bottom face is 0.2 m below the tcp
    # (the CPR's tool points down at this pose), so the gap is 0.3 - 0.2 - 0.05
    below = ck.Obstacle.sphere(0.05, tcp + np.array([0.0, 0.0, -0.3]), name="ball")
    clearance = ck.CollisionWorld(carried, [below]).clearance(Q)
    assert clearance.closest is not None and clearance.closest.robot_geometry == PAYLOAD_GEOMETRY
    assert clearance.min_clearance_m == pytest.approx(0.05, abs=1e-6)


SCENE: dict[str, Any] = {
    "start": {"q": [0.0, 0.1, 0.1, 0.0, 0.0]},
    "goal": {"q": [1.5, 0.5, 0.4, 1.0, 0.5]},
    "payload": {"mass_kg": 2.0, "shape": {"shape": "box", "size": [0.08, 0.08, 0.2], "xyz": [0, 0, -0.1]}},
}


def test_the_shape_round_trips_through_the_scene_file() -> None:
    scene = parse_scene(SCENE)
    assert scene.payload is not None and scene.payload.shape is not None
    again = parse_scene(scene_document(scene))
    assert again.payload is not None and again.payload.shape is not None
    assert again.payload.shape.shape == "box"
    assert np.allclose(np.asarray(again.payload.shape.size), [0.08, 0.08, 0.2])


@pytest.mark.parametrize(
    ("shape", "code", "message"),
    [
        ({"shape": "box", "size": [0.08, 0.08, 0.2], "xyz": [0, 0, 0.1]}, 2, "arm is -0.040 m from payload"),
        (
            {"shape": "mesh", "mesh": "a.stl", "xyz": [0, 0, 0]},
            2,
            "payload: obstacle 'payload': mesh file",
        ),
        (
            {"shape": "cone", "radius": 0.05, "xyz": [0, 0, 0]},
            2,
            "allowed: box, sphere, cylinder, capsule, mesh\n",
        ),
        (
            {"shape": "sphere", "radius": 0.05, "xyz": [0, 0, 0], "colour": 1},
            2,
            "payload.shape.colour: unknown key",
        ),
    ],
)
def test_a_shape_in_the_arm_or_a_bad_shape_is_refused(
    shape: dict[str, Any], code: int, message: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump({**SCENE, "payload": {"mass_kg": 1.0, "shape": shape}}))
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == code
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1, err
    assert not (tmp_path / "out").exists()


def test_touch_links_are_left_out_of_the_shapes_self_pairs(robot: ck.Robot) -> None:
    touching = ck.carrying(robot, ck.Payload(1.0, shape=BOX, touch_links=("arm_link",), name="part"))
    added = touching.geometries[-1]
    assert added.name == "part"
    partners = {touching.geometries[a].link for a, b in touching.self_pairs if b == added.index}
    assert partners == {"base_link", "column_link", "carriage_link"}
    with pytest.raises(ck.CprKinError, match=r"touch_links \['hand'\] are not links of the robot; its links"):
        ck.carrying(robot, ck.Payload(1.0, shape=BOX, touch_links=("hand",)))


def test_a_shape_that_touches_a_touch_link_plans_and_passes_check(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the box reaching up into the arm is refused at the start (above); the arm may touch it
    into_the_arm = {"shape": "box", "size": [0.08, 0.08, 0.2], "xyz": [0, 0, 0.1]}
    payload = {"name": "rod", "mass_kg": 1.0, "shape": into_the_arm, "touch_links": ["arm_link"]}
    scene = tmp_path / "scene.yaml"
    scene.write_text(yaml.safe_dump({**SCENE, "payload": payload}))
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 0, capsys.readouterr().err
    assert main(["check", str(scene), str(tmp_path / "out" / "trajectory.json")]) == 0
    again = parse_scene(scene_document(parse_scene(yaml.safe_load(scene.read_text()))))
    assert again.payload is not None and again.payload.touch_links == ("arm_link",)
    assert again.payload.name == "rod"


def test_a_mesh_shape_is_its_convex_hull(robot: ck.Robot, tmp_path: Path) -> None:
    import trimesh

    mesh = trimesh.creation.box(extents=(0.08, 0.08, 0.2))
    mesh.export(tmp_path / "part.stl")
    as_mesh = ck.Obstacle.from_mesh(tmp_path / "part.stl", (0.0, 0.0, -0.1), convex=False, name="part")
    carried = ck.carrying(robot, ck.Payload(1.0, shape=as_mesh))
    tcp = ck.frame_positions(carried, Q)
    below = ck.Obstacle.sphere(0.05, tcp + np.array([0.0, 0.0, -0.3]), name="ball")
    clearance = ck.CollisionWorld(carried, [below]).clearance(Q)  # as the box's (above)
    assert clearance.closest is not None and clearance.closest.robot_geometry == PAYLOAD_GEOMETRY
    assert clearance.min_clearance_m == pytest.approx(0.05, abs=1e-6)
