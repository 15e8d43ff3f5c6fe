from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

import cpr_kin as ck
from cpr_kin.kinematics.tool_chain import ToolChain
from cpr_kin.model.packages import example_robot

from .conftest import random_configurations

FRAMES = ["tcp", "column_link", "carriage_link", "arm_link", "wrist_link", "tool_link"]


@pytest.fixture(scope="module")
def urdf() -> yourdfpy.URDF:
    return yourdfpy.URDF.load(str(ck.cpr_urdf_path()), build_scene_graph=True, load_meshes=False)


def test_pinocchio_agrees_with_yourdfpy(
    robot: ck.Robot, urdf: yourdfpy.URDF, rng: np.random.Generator
) -> None:
    configurations = random_configurations(robot, rng, 50)
    for frame in FRAMES:
        poses = ck.frame_poses(robot, configurations, frame)
        for q, pose in zip(configurations, poses, strict=True):
            urdf.update_cfg(q)
            np.testing.assert_allclose(pose, urdf.get_transform(frame, "base_link"), atol=1e-9, rtol=0)


def test_tcp_matches_design_formula(robot: ck.Robot, rng: np.random.Generator) -> None:
    # docs/robot.md: with theta4 = theta5 = 0, tcp = (r_f cos t1, r_f sin t1, z_c - 0.15)
    configurations = random_configurations(robot, rng, 200)
    configurations[:, 3:] = 0.0
    theta1, d2, d3 = configurations[:, 0], configurations[:, 1], configurations[:, 2]
    r_f, z_c = 0.30 + d3, 0.25 + d2
    expected = np.column_stack([r_f * np.cos(theta1), r_f * np.sin(theta1), z_c - 0.15])
    np.testing.assert_allclose(ck.frame_positions(robot, configurations), expected, atol=1e-12)


def test_arm_rear_end_behind_column(robot: ck.Robot) -> None:
    # arm frame = flange at r_f = 0.30 + d3; the beam's rear end lies 0.70 behind it
    pose = ck.frame_poses(robot, [0.0, 0.0, 0.0, 0.0, 0.0], "arm_link")
    np.testing.assert_allclose(pose[:3, 3], [0.30, 0.0, 0.25], atol=1e-12)
    arm = robot.collision_model.geometryObjects[[g.name for g in robot.geometries].index("arm")]
    np.testing.assert_allclose(arm.placement.translation, [-0.35, 0.0, 0.0])
    np.testing.assert_allclose(2 * arm.geometry.halfSide, [0.70, 0.05, 0.05])


def test_single_equals_batch(robot: ck.Robot, rng: np.random.Generator) -> None:
    configurations = random_configurations(robot, rng, 5)
    batch = ck.frame_positions(robot, configurations)
    assert batch.shape == (5, 3)
    for q, p in zip(configurations, batch, strict=True):
        np.testing.assert_array_equal(ck.frame_positions(robot, q), p)


def test_batch_shape_error(robot: ck.Robot) -> None:
    with pytest.raises(ValueError, match=r"expected \(nq,\) or \(N, nq\)"):
        ck.frame_positions(robot, np.zeros((3, 4)))


@pytest.mark.parametrize("name", ["panda", "ur5"])
def test_every_frame_is_placed_as_pinocchio_places_it(name: str) -> None:
    """The compiled chain against Pinocchio's own forward kinematics, every frame of the model."""
    robot = ck.load_robot(example_robot(name))
    configurations = ck.sampled_configurations(robot.model, 20, np.random.default_rng(3))
    for frame in robot.model.frames:
        fid = robot.model.getFrameId(frame.name, frame.type)
        if robot.frame_id(frame.name) != fid:  # a name two frames share: the link's is the one named
            continue
        poses = ck.frame_poses(robot, configurations, frame.name)
        for q, pose in zip(configurations, poses, strict=True):
            pin.forwardKinematics(robot.model, robot.data, q)
            expected = pin.updateFramePlacement(robot.model, robot.data, fid).homogeneous
            np.testing.assert_allclose(pose, expected, atol=1e-12, rtol=0)


def test_a_robots_chain_to_a_frame_is_made_once(robot: ck.Robot) -> None:
    assert ToolChain.of(robot, "arm_link") is ToolChain.of(robot, "arm_link")
    assert ToolChain.of(robot) is ToolChain.of(robot, robot.tcp_frame)
    assert ToolChain.of(robot, "arm_link") is not ToolChain.of(robot)
