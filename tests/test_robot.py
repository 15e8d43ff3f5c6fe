from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.model.robot import joint_units

URDF_TEXT = ck.cpr_urdf_path().read_text()


def test_joints_and_limits_match_design(robot: ck.Robot) -> None:
    assert robot.joint_names == ("theta1", "d2", "d3", "theta4", "theta5")
    lim = robot.limits
    np.testing.assert_array_equal(lim.lower, [-2.9, 0.0, 0.0, -3.1, -1.6])
    np.testing.assert_array_equal(lim.upper, [2.9, 0.6, 0.5, 3.1, 1.6])
    np.testing.assert_array_equal(lim.velocity, [1.5, 0.5, 0.5, 2.0, 2.0])
    np.testing.assert_array_equal(lim.acceleration, [3.0, 2.0, 2.0, 4.0, 4.0])
    np.testing.assert_array_equal(lim.jerk, [15.0, 10.0, 10.0, 20.0, 20.0])
    assert [robot.joint_unit(n) for n in robot.joint_names] == ["rad", "m", "m", "rad", "rad"]
    assert robot.joint_units == ("rad", "m", "m", "rad", "rad") == joint_units(robot.model)


def test_speed_scales_and_move_times_follow_the_limits(robot: ck.Robot) -> None:
    lim = robot.limits  # the CPR's velocities [1.5, 0.5, 0.5, 2.0, 2.0]: the wrist's the fastest
    np.testing.assert_allclose(lim.speed_scales, [0.75, 0.25, 0.25, 1.0, 1.0], rtol=1e-15)
    change = np.array([[0.0, 0.3, 0.0, 0.0, 0.0], [1.2, 0.0, 0.0, 0.0, -0.1], [0.0] * 5])
    # d2: 0.3 m >= v^2 / a = 0.125 m, cruises: 0.3 / 0.5 + 0.5 / 2; theta1: 1.2 rad >= 0.75 rad,
    # cruises: 1.2 / 1.5 + 1.5 / 3, slower than theta5's triangle 2 sqrt(0.1 / 4)
    np.testing.assert_allclose(lim.move_time_s(change), [0.85, 1.3, 0.0], rtol=1e-12)
    assert lim.move_time_s(change[1]) == pytest.approx(1.3)  # one change: one time
    assert lim.speeds_differ
    assert not dataclasses.replace(lim, velocity=np.full(robot.nq, 0.5)).speeds_differ


def test_collision_groups(robot: ck.Robot) -> None:
    groups = {g.name: g.group for g in robot.geometries}
    assert groups == {
        "base": "links",
        "column": "links",
        "carriage": "links",
        "arm": "links",
        "wrist": "effector",
        "tool": "effector",
    }
    assert [g.name for g in robot.group_geometries("effector")] == ["wrist", "tool"]
    with pytest.raises(ck.CprKinError, match="unknown collision group 'hand'"):
        robot.group_geometries("hand")


def test_missing_urdf(tmp_path: Path) -> None:
    missing = tmp_path / "nope.urdf"
    with pytest.raises(ck.UrdfError, match=r"nope\.urdf' does not exist"):
        ck.load_cpr(missing)


def test_malformed_xml(tmp_path: Path) -> None:
    path = tmp_path / "broken.urdf"
    path.write_text(URDF_TEXT[: len(URDF_TEXT) // 2])
    with pytest.raises(ck.UrdfError, match=re.escape("broken.urdf' is not well-formed XML")):
        ck.load_cpr(path)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('<robot name="arm"></robot>', r"empty\.urdf' has no <link>: an empty robot"),
        ('<robot><link name="base"/></robot>', r"empty\.urdf': <robot> has no name attribute"),
        (
            '<sdf version="1.6"><model name="arm"/></sdf>',
            r"empty\.urdf' has root element <sdf>; a URDF's root is <robot",
        ),
    ],
    ids=["no link", "no name", "not a robot"],
)
def test_a_urdf_that_is_no_robot_is_refused_by_name(tmp_path: Path, text: str, message: str) -> None:
    # example-robot-data's ur3.urdf is an empty <robot> (xacro run without arguments); yourdfpy
    # said only "cannot be read: 'name'"
    path = tmp_path / "empty.urdf"
    path.write_text(text)
    for validate in (True, False):
        with pytest.raises(ck.UrdfError, match=message):
            ck.load_cpr(path, validate=validate)


def test_urdf_with_dangling_joint_is_invalid(tmp_path: Path) -> None:
    path = tmp_path / "dangling.urdf"
    path.write_text(URDF_TEXT.replace('<child link="tcp"/>', '<child link="no_such_link"/>'))
    with pytest.raises(ck.UrdfError, match=re.escape("dangling.urdf")):
        ck.load_cpr(path)


def test_user_urdf_is_validated_by_yourdfpy(tmp_path: Path) -> None:
    # yourdfpy names the problem where Pinocchio only says "does not contain a valid URDF model"
    path = tmp_path / "hinge.urdf"
    path.write_text(URDF_TEXT.replace('type="revolute"', 'type="hinge"', 1))
    with pytest.raises(ck.UrdfError, match=r"hinge\.urdf' is invalid: .*'type' attribute"):
        ck.load_cpr(path)
    with pytest.raises(ck.UrdfError, match="joint 'theta1' is of type 'hinge'; supported"):
        ck.load_cpr(path, validate=False)


def test_bundled_urdf_passes_yourdfpy_validation() -> None:
    # loading the bundled URDF skips the validation (0.7 s of importing trimesh): this is its check
    robot = ck.load_cpr(validate=True)
    assert robot.joint_names == ck.CPR_JOINTS


def test_collision_names_agree_with_yourdfpy(tmp_path: Path) -> None:
    import yourdfpy

    # unnamed collisions: a link's only one takes the link's name, several are numbered
    text = URDF_TEXT.replace('<collision name="base">', "<collision>").replace(
        '<collision name="wrist">', "<collision>"
    )
    head, tail = text.split('<collision name="tool">', 1)
    body, rest = tail.split("</collision>", 1)
    text = f"{head}<collision>{body}</collision><collision>{body}</collision>{rest}"
    path = tmp_path / "unnamed.urdf"
    path.write_text(text)
    urdf = yourdfpy.URDF.load(str(path), build_scene_graph=False, load_meshes=False)
    expected = [
        c.name or (link.name if len(link.collisions) == 1 else f"{link.name}_{i}")
        for link in urdf.robot.links
        for i, c in enumerate(link.collisions)
    ]
    robot = ck.load_cpr(path)
    assert sorted(g.name for g in robot.geometries) == sorted(expected)
    assert {"base_link", "wrist_link", "tool_link_0", "tool_link_1"} <= {g.name for g in robot.geometries}


def test_urdf_without_a_cpr_joint(tmp_path: Path) -> None:
    path = tmp_path / "renamed.urdf"
    path.write_text(URDF_TEXT.replace('joint name="d3"', 'joint name="slide"'))
    with pytest.raises(ck.UrdfError, match=r"has no joint\(s\) \['d3'\]; its joints are"):
        ck.load_cpr(path)


def test_urdf_without_tcp(tmp_path: Path) -> None:
    path = tmp_path / "notcp.urdf"
    path.write_text(
        URDF_TEXT.replace('<link name="tcp"/>', '<link name="tip"/>').replace(
            '<child link="tcp"/>', '<child link="tip"/>'
        )
    )
    with pytest.raises(ck.UrdfError, match="no link or frame named 'tcp'"):
        ck.load_cpr(path)


def test_limits_file_disagreeing_velocity(tmp_path: Path) -> None:
    (tmp_path / "cpr.urdf").write_text(URDF_TEXT)
    text = (
        ck.cpr_limits_path()
        .read_text()
        .replace(
            "velocity: 0.5, acceleration: 2.0, jerk: 10.0}",
            "velocity: 0.7, acceleration: 2.0, jerk: 10.0}",
            1,
        )
    )
    (tmp_path / "cpr_limits.yaml").write_text(text)
    with pytest.raises(
        ck.UrdfError, match=re.escape("joint 'd2' velocity 0.7 disagrees with the URDF's 0.5")
    ):
        ck.load_cpr(tmp_path / "cpr.urdf")


def test_a_velocity_the_urdf_leaves_out_comes_from_the_limits_file(tmp_path: Path) -> None:
    # description-only URDFs often give velocity="0": the limits file may give it instead
    no_speed = URDF_TEXT.replace(
        '<limit lower="0.0" upper="0.6" velocity="0.5" effort="200"/>',
        '<limit lower="0.0" upper="0.6" velocity="0" effort="200"/>',
    )
    assert no_speed != URDF_TEXT
    (tmp_path / "cpr.urdf").write_text(no_speed)
    limits = ck.cpr_limits_path().read_text()
    (tmp_path / "cpr_limits.yaml").write_text(
        limits.replace("d2:     {velocity: 0.5, acceleration: 2.0, jerk: 10.0}", "d2:     {velocity: 0.4}")
    )
    robot = ck.load_cpr(tmp_path / "cpr.urdf")
    d2 = robot.limits.index("d2")
    assert robot.limits.velocity[d2] == 0.4 and robot.model.velocityLimit[d2] == 0.4
    assert robot.limits.acceleration[d2] == pytest.approx(0.8)  # the default 2 v of the file's v
    (tmp_path / "cpr_limits.yaml").write_text(
        limits.replace("d2:     {velocity: 0.5, acceleration: 2.0, jerk: 10.0}", "d2:     {jerk: 10.0}")
    )
    with pytest.raises(
        ck.UrdfError,
        match=r"joint\(s\) \['d2'\] have no velocity limit .*give <limit velocity=...> in the URDF, "
        r"or 'velocity' in the limits file '.*cpr_limits\.yaml'",
    ):
        ck.load_cpr(tmp_path / "cpr.urdf")


def test_limits_file_unknown_joint(tmp_path: Path) -> None:
    (tmp_path / "cpr.urdf").write_text(URDF_TEXT)
    (tmp_path / "cpr_limits.yaml").write_text(
        ck.cpr_limits_path().read_text() + "elbow: {acceleration: 1, jerk: 1}\n"
    )
    planned = r"the planned joints are \['theta1', 'd2', 'd3', 'theta4', 'theta5'\] \(the URDF's other"
    with pytest.raises(ck.UrdfError, match=rf"unknown joint\(s\) \['elbow'\]; {planned}"):
        ck.load_cpr(tmp_path / "cpr.urdf")


@pytest.mark.parametrize(
    ("values", "pattern"),
    [
        ([0.0, 0.75, 0.1, 0.0, 0.0], r"joint 'd2' = 0\.75 m is outside \[0, 0\.6\] m"),
        ([3.0, 0.1, 0.1, 0.0, 0.0], r"joint 'theta1' = 3 rad is outside \[-2\.9, 2\.9\] rad"),
        ([0.0, 0.1, math.nan, 0.0, 0.0], r"joint 'd3' = nan is not a finite number"),
        ([0.0, 0.1, 0.1], r"has 3 value\(s\); expected 5, one per planned joint"),
        ({"theta1": 0.0, "elbow": 1.0}, r"unknown joint 'elbow'"),
        ({"theta1": 0.0, "d2": 0.1}, r"lack joint\(s\) \['d3', 'theta4', 'theta5'\]"),
        ("abc", r"must be 5 numbers"),
    ],
)
def test_bad_configurations(robot: ck.Robot, values: object, pattern: str) -> None:
    with pytest.raises(ck.CprKinError, match=pattern):
        robot.configuration(values)  # type: ignore[arg-type]


def test_configuration_from_mapping(robot: ck.Robot) -> None:
    q = robot.configuration({"theta5": 0.5, "theta4": 0.4, "d3": 0.3, "d2": 0.2, "theta1": 0.1})
    np.testing.assert_array_equal(q, [0.1, 0.2, 0.3, 0.4, 0.5])


def test_unknown_frame(robot: ck.Robot) -> None:
    with pytest.raises(ck.CprKinError, match="unknown frame 'gripper'"):
        robot.frame_id("gripper")


def test_frames_fixed_together_keep_their_relative_pose(robot: ck.Robot) -> None:
    # the oracle: two frames move as one exactly where their relative placement is the same at
    # every configuration (Pinocchio's forward kinematics at seeded random ones)
    names = sorted({f.name for f in robot.model.frames if f.name != "universe"})
    rng = np.random.default_rng(7)
    draws = rng.uniform(robot.limits.lower, robot.limits.upper, size=(5, robot.nq))
    poses = {name: ck.frame_poses(robot, draws, name) for name in names}
    for first in names:
        for second in names:
            relative = np.linalg.inv(poses[first]) @ poses[second]
            constant = np.allclose(relative, relative[0], atol=1e-9)
            assert robot.fixed_together(first, second) == constant, (first, second)
    assert robot.fixed_together("tool_link", "tcp") and not robot.fixed_together("tcp", "base_link")
    with pytest.raises(ck.CprKinError, match="unknown frame 'gripper'"):
        robot.fixed_together("tcp", "gripper")


def test_bad_limits_dataclass() -> None:
    with pytest.raises(ck.CprKinError, match=re.escape("jerk limit 0.0 must be > 0")):
        ck.JointLimits(
            names=("a",),
            lower=np.zeros(1),
            upper=np.ones(1),
            velocity=np.ones(1),
            acceleration=np.ones(1),
            jerk=np.zeros(1),
        )
