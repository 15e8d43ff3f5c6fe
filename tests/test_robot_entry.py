"""A scene's ``robot:`` entry and its targets for any robot: names, paths, mappings, poses, round trips."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
import yaml

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning.errors import SceneError
from planning.io.robot_entry import RobotMapping, robot_entry, robot_spec_of
from planning.io.scene_file import dump_scene, load_scene, parse_scene, scene_to_dict

PANDA_START = {"q": [0.0, -0.6, 0.0, -2.2, 0.0, 1.6, 0.8]}
PANDA_GOAL = {"pose": {"xyz": [0.45, 0.35, 0.25], "rpy": [3.14159, 0.0, 0.0]}}


def scene_file(folder: Path, document: dict[str, Any]) -> Path:
    path = folder / "scene.yaml"
    path.write_text(yaml.safe_dump(document))
    return path


def test_a_robot_by_name_is_example_robot_datas() -> None:
    scene = parse_scene({"robot": "panda", "start": PANDA_START, "goal": PANDA_GOAL})
    assert scene.robot is not None and scene.robot.urdf == example_robot("panda")
    robot = scene.robot.load()
    assert robot.nq == 7 and robot.tcp_frame == "panda_hand_tcp"


def test_the_bundled_robot_by_name_is_the_default_and_takes_a_mapping_s_keys() -> None:
    # 'cpr' named the bundled robot on the command line (robot-info, --urdf) but not in a scene
    ends = {"start": {"q": [0.0, 0.3, 0.3, 0.0, 0.0]}, "goal": {"q": [0.5, 0.3, 0.3, 0.0, 0.0]}}
    assert parse_scene({"robot": "cpr", **ends}).robot == parse_scene(ends).robot == ck.cpr_spec()
    scene = parse_scene({"robot": {"urdf": "cpr", "tcp": "tool_link"}, **ends})
    assert scene.robot is not None and scene.robot.urdf == ck.cpr_urdf_path()
    assert scene.robot.load().tcp_frame == "tool_link" and scene.robot.joints == ck.CPR_JOINTS
    with pytest.raises(SceneError, match=r"the bundled 'cpr'.*did you mean 'cpr'"):
        parse_scene({"robot": "cpt", **ends})


def test_a_urdf_path_is_relative_to_the_scene_file(tmp_path: Path) -> None:
    (tmp_path / "robots").mkdir()
    shutil.copy(ck.load_cpr().urdf_path, tmp_path / "robots" / "my_cpr.urdf")
    scene = load_scene(
        scene_file(
            tmp_path, {"robot": "robots/my_cpr.urdf", "start": {"q": [0] * 5}, "goal": {"q": [0.1] * 5}}
        )
    )
    assert scene.robot is not None and scene.robot.urdf == tmp_path / "robots" / "my_cpr.urdf"
    assert scene.robot.joints == ck.CPR_JOINTS  # a URDF with the CPR's joints gets the CPR preset


def test_a_mapping_sets_joints_tool_held_values_and_files(tmp_path: Path) -> None:
    srdf = example_robot("panda").parent.parent / "srdf" / "panda.srdf"
    (tmp_path / "config").mkdir()
    shutil.copy(srdf, tmp_path / "config" / "arm.srdf")
    (tmp_path / "config" / "limits.yaml").write_text(
        yaml.safe_dump({f"panda_joint{k}": {"acceleration": 5.0, "jerk": 500.0} for k in range(1, 8)})
    )
    entry = {
        "urdf": "panda",
        "srdf": "config/arm.srdf",
        "limits": "config/limits.yaml",
        "joints": [f"panda_joint{k}" for k in range(1, 7)],
        "tcp": "panda_link8",
        "fixed": {"panda_joint7": 0.5, "panda_finger_joint1": 0.02},
    }
    scene = load_scene(
        scene_file(
            tmp_path, {"robot": entry, "start": {"q": [0.0, -0.6, 0.0, -2.2, 0.0, 1.6]}, "goal": PANDA_GOAL}
        )
    )
    spec = scene.robot
    assert spec is not None and spec.srdf == tmp_path / "config" / "arm.srdf"
    robot = spec.load()
    assert robot.nq == 6 and robot.tcp_frame == "panda_link8"
    assert dict(robot.held) == {"panda_joint7": 0.5, "panda_finger_joint1": 0.02, "panda_finger_joint2": 0.02}
    assert robot.limits_path == tmp_path / "config" / "limits.yaml" and robot.limits_defaulted == ()
    np.testing.assert_array_equal(robot.limits.acceleration, 5.0)
    # written back as a mapping of absolute paths, it reads as the same spec from any folder
    assert robot_spec_of(RobotMapping(**robot_entry(spec)), base=Path("/elsewhere")) == spec
    dump_scene(scene, tmp_path / "config" / "again.yaml")
    assert load_scene(tmp_path / "config" / "again.yaml").robot == spec


def test_a_scene_with_a_pose_goal_round_trips_through_its_file(tmp_path: Path) -> None:
    scene = parse_scene(
        {"robot": "ur5", "start": {"q": [0.0, -1.2, 1.2, -1.0, 1.0, 0.0]}, "goal": PANDA_GOAL}
    )
    dump_scene(scene, tmp_path / "again.yaml")
    again = load_scene(tmp_path / "again.yaml")
    assert again.robot == scene.robot and again.start == scene.start
    assert again.goal.pose is not None and scene.goal.pose is not None
    np.testing.assert_allclose(again.goal.pose[0], scene.goal.pose[0])
    np.testing.assert_allclose(again.goal.pose[1], scene.goal.pose[1], atol=1e-12)


def test_a_quaternion_and_roll_pitch_yaw_give_the_same_pose() -> None:
    rpy = (0.3, -0.2, 1.1)
    quaternion = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy))
    by_rpy = parse_scene(
        {"robot": "panda", "start": PANDA_START, "goal": {"pose": {"xyz": [0.4, 0, 0.4], "rpy": list(rpy)}}}
    )
    by_quaternion = parse_scene(
        {
            "robot": "panda",
            "start": PANDA_START,
            "goal": {
                "pose": {
                    "xyz": [0.4, 0, 0.4],
                    "quat_xyzw": [quaternion.x, quaternion.y, quaternion.z, quaternion.w],
                }
            },
        }
    )
    assert by_rpy.goal.pose is not None and by_quaternion.goal.pose is not None
    np.testing.assert_allclose(by_rpy.goal.pose[1], by_quaternion.goal.pose[1], atol=1e-12)


@pytest.mark.parametrize(
    ("quat_xyzw", "rotation"),
    [
        ([1.0000000001, 0, 0, 0], np.diag([1.0, -1.0, -1.0])),  # rounding: normalised
        ([0.7071, 0, 0, 0.7071], pin.rpy.rpyToMatrix(np.pi / 2, 0, 0)),  # printed to 4 digits
        ([0.9, 0.9, 0, 0], None),  # not a rotation: refused, with the one it may mean
        ([0.0, 0.0, 0.0, 1.0005], np.eye(3)),
        ([0.0, 0.0, 0.0, 1.002], None),
    ],
)
def test_a_quaternion_is_normalised_within_the_stated_tolerance_and_refused_beyond(
    quat_xyzw: list[float], rotation: np.ndarray | None
) -> None:
    from planning.validation import QUATERNION_NORM_TOLERANCE

    document = {
        "robot": "panda",
        "start": PANDA_START,
        "goal": {"pose": {"xyz": [0.4, 0, 0.4], "quat_xyzw": quat_xyzw}},
    }
    if rotation is None:
        with pytest.raises(
            SceneError, match=rf"quat_xyzw = .*has norm .*within {QUATERNION_NORM_TOLERANCE:g}"
        ):
            parse_scene(document)
        return
    pose = parse_scene(document).goal.pose
    assert pose is not None
    np.testing.assert_allclose(np.array(pose[1]), rotation, atol=1e-4)
    np.testing.assert_allclose(np.array(pose[1]) @ np.array(pose[1]).T, np.eye(3), atol=1e-12)  # a rotation


@pytest.mark.parametrize(
    ("change", "pattern"),
    [
        ({"goal": {"pose": {"xyz": [0.4, 0, 0.4]}}}, "give exactly one of 'quat_xyzw' [x, y, z, w] or 'rpy'"),
        (
            {"goal": {"pose": {"xyz": [0.4, 0, 0.4], "rpy": [0, 0, 0], "quat_xyzw": [0, 0, 0, 1]}}},
            "give exactly one of 'quat_xyzw'",
        ),
        (
            {"goal": {"pose": {"xyz": [0.4, 0, 0.4], "quat_xyzw": [0, 0, 0, 0]}}},
            "has norm 0; a rotation",
        ),
        ({"goal": {"tcp": [0.4, 0, 0.4], "tolerance_m": 0.5}}, "goal.tolerance_m = 0.5"),
        (
            {"robot": {"urdf": "panda", "gripper": "hand"}},
            "robot.gripper: unknown key; allowed here: urdf, srdf",
        ),
        ({"robot": {"urdf": "panda", "joints": []}}, "robot.joints: 0 items; needs at least 1"),
        ({"robot": 3}, "robot = 3: Input should be a valid string"),
        (
            {"robot": {"urdf": "panda", "fixed": {"panda_finger_joint1": float("nan")}}},
            "robot.fixed.panda_finger_joint1 = nan: Input should be a finite number",
        ),
        ({"start": {"q": [0.0, "x"]}}, "start.q[1] = 'x': Input should be a valid number"),
        (
            {"start": {"q": {"panda_joint1": "up"}}},
            "start.q.panda_joint1 = 'up': Input should be a valid number",
        ),
        (
            {"goal": {"pose": {"xyz": [0, 0, 0], "rpy": [0, 0, 0], "w": 1}}},
            "goal.pose.w: unknown key; allowed here: xyz",
        ),
    ],
)
def test_bad_entries_name_the_key_and_value(change: dict[str, Any], pattern: str) -> None:
    with pytest.raises(SceneError) as info:
        parse_scene({"robot": "panda", "start": PANDA_START, "goal": PANDA_GOAL, **change}, source="s.yaml")
    assert pattern in str(info.value)


def test_a_scene_without_a_robot_reads_as_the_cpr_and_is_written_without_one() -> None:
    scene = parse_scene({"start": {"q": [0.0, 0.3, 0.3, 0.0, 0.0]}, "goal": {"q": [0.5, 0.3, 0.3, 0.0, 0.0]}})
    assert scene.robot == ck.cpr_spec() == ck.robot_spec(ck.cpr_urdf_path())
    assert "robot" not in scene_to_dict(scene)  # read back, the same default
    named = parse_scene({"robot": "panda", "start": PANDA_START, "goal": PANDA_GOAL})
    assert named.robot is not None and scene_to_dict(named)["robot"] == robot_entry(named.robot)


def test_a_scene_made_without_a_robot_is_planned_only_with_one_given() -> None:
    from planning import Scene, Target, plan
    from planning.errors import PlanningError

    scene = Scene(start=Target(q=(0.0, 0.3, 0.3, 0.0, 0.0)), goal=Target(q=(0.5, 0.3, 0.3, 0.0, 0.0)))
    with pytest.raises(PlanningError, match=r"scene 'scene' names no robot: give Scene\(robot=...\)"):
        plan(scene)
