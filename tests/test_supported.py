"""What the planner supports of a URDF: absurd joints are refused at load, naming the joint."""

from __future__ import annotations

import dataclasses
import json
import math
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.description.supported import MAX_CROSSING_S, crossing_time
from cpr_kin.model.limits import DEFAULT_ACCELERATION_PER_S, DEFAULT_JERK_PER_S
from cpr_kin.model.packages import example_robot_data_share
from planning import PlannerSettings, Scene, Target, paper_scene, plan
from planning.cli import main
from planning.io.report import limits_section

URDF = ck.cpr_urdf_path().read_text()
THETA1 = '<limit lower="-2.9" upper="2.9" velocity="1.5" effort="100"/>'


def variant(folder: Path, edit: Callable[[str], str], name: str = "robot.urdf") -> Path:
    path = folder / name
    path.write_text(edit(URDF))
    # the bundled limits without their velocities (which must agree with the URDF's)
    limits = re.sub(r"velocity: [0-9.]+, ", "", ck.cpr_limits_path().read_text())
    (folder / "cpr_limits.yaml").write_text(limits)
    return path


def theta1_limit(lower: str, upper: str, velocity: str = "1.5") -> Callable[[str], str]:
    return lambda text: text.replace(
        THETA1, f'<limit lower="{lower}" upper="{upper}" velocity="{velocity}" effort="100"/>'
    )


BRACE = '<joint name="brace" type="fixed"><parent link="base_link"/><child link="arm_link"/></joint>'
SUPPORTED = (
    r"the planner supports lower < upper with a part within \[-6.2832, 6.2832\] rad, one turn either way "
    r"\(a wider range is planned within it\)$"
)
REFUSED = [
    ("range beyond a turn", theta1_limit("7", "1000"),
     r"joint 'theta1' range \[7, 1000\] rad is not supported; " + SUPPORTED),
    ("range 1e12 below", theta1_limit("-1e12", "-6.3"), r"'theta1' range \[-1e\+12, -6.3\] rad is not"),
    ("empty range", theta1_limit("0.5", "0.5"), r"joint 'theta1' range \[0.5, 0.5\] rad is not supported"),
    ("slow joint", theta1_limit("-2.9", "2.9", "1e-6"),
     r"joint 'theta1' needs 5.8e\+06 s to cross its range .* at most 600 s: raise the limits"),
    ("planar", lambda t: t.replace('name="d2" type="prismatic"', 'name="d2" type="planar"'),
     r"joints names \['d2'\], a base's planar or floating joint\(s\): they are held at their identity pose"),
    ("mimic", lambda t: t.replace('<joint name="theta5" type="revolute">',
                                  '<joint name="theta5" type="revolute"><mimic joint="theta4"/>'),
     r"joint\(s\) \['theta5'\] mimic another; they cannot be planned"),
    ("zero axis", lambda t: t.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1),
     r"joint 'theta1' axis xyz = '0 0 0' is not a direction"),
    ("bidirectional name", lambda t: t.replace('"d2"', '"d\u202e2"'),
     r"the joint name 'd\\u202e2' holds U\+202E \(RIGHT-TO-LEFT OVERRIDE\)"),
    ("control character", lambda t: t.replace('link name="tcp"', 'link name="t\x85cp"'),
     r"the link name 't\\x85cp' holds U\+0085"),
    ("closed loop", lambda t: t.replace('<parent link="base_link"/><child link="column_link"/>',
                                        '<parent link="tool_link"/><child link="column_link"/>'),
     r"joints 'd2' \(column_link -> carriage_link\), 'd3' \(carriage_link -> arm_link\), "
     r"'theta4' \(arm_link -> wrist_link\), 'theta5' \(wrist_link -> tool_link\), "
     r"'theta1' \(tool_link -> column_link\) close a loop, which hangs from no root link"),
    ("two parents", lambda t: t.replace("</robot>", BRACE + "</robot>"),
     r"link 'arm_link' is the child of joints 'd3' and 'brace'; a link hangs from one joint at most"),
    ("second root", lambda t: t.replace("</robot>", '<link name="stray"/></robot>'),
     r"links 'base_link', 'stray' are each the child of no joint; .* join the others to 'base_link's tree"),
    ("undefined link", lambda t: t.replace('<child link="tcp"/>', '<child link="tpc"/>'),
     r"joint 'tcp_joint' names child link 'tpc', which the file does not define; a joint joins two of its "
     r"links \('base_link', 'column_link', .* 'tcp'\)"),
    ("link defined twice", lambda t: t.replace('<link name="tcp"/>', '<link name="tcp"/><link name="tcp"/>'),
     r"link name\(s\) 'tcp' are defined more than once"),
    ("NaN lower limit", theta1_limit("nan", "2.9"),
     r"joint 'theta1' limit lower = 'nan' is not supported; give a finite number$"),
    ("velocity below zero", theta1_limit("-2.9", "2.9", "-1.5"),
     r"joint 'theta1' limit velocity = '-1.5' is not supported; give a finite number >= 0"),
    ("NaN radius", lambda t: t.replace('radius="0.15"', 'radius="nan"', 1),
     r"link 'base_link': (visual|collision) cylinder radius = 'nan' is not supported; give a number in"),
    ("box side below zero", lambda t: t.replace('size="0.12 0.12 0.9"', 'size="0.12 -0.12 0.9"'),
     r"link 'column_link': (visual|collision) box size = '0.12 -0.12 0.9' is not supported; give 3 numbers"),
    ("box of 1e30 m", lambda t: t.replace('size="0.12 0.12 0.9"', 'size="0.12 0.12 1e30"'),
     r"box size = '0.12 0.12 1e30' is not supported; give 3 numbers in [\(\[]0, 100\] m"),
    ("NaN mass", lambda t: t.replace('mass value="10.0"', 'mass value="nan"'),
     r"link 'base_link' inertial mass = 'nan' is not a finite number"),
    ("mass below zero", lambda t: t.replace('mass value="10.0"', 'mass value="-10.0"'),
     r"link 'base_link' inertial mass = -10 kg is below zero; a body's is at least zero"),
    ("moment below zero", lambda t: t.replace('ixx="0.065"', 'ixx="-0.065"', 1),
     r"link 'base_link' inertial ixx = -0.065 kg m\^2 is below zero"),
]  # fmt: skip


@pytest.mark.parametrize(("label", "edit", "message"), REFUSED, ids=[case[0] for case in REFUSED])
def test_an_unsupported_urdf_is_refused_at_load_naming_the_joint(
    tmp_path: Path, label: str, edit: Callable[[str], str], message: str
) -> None:
    with pytest.raises(ck.UrdfError, match=message):
        ck.load_cpr(variant(tmp_path, edit))


BASE_VISUAL = '<cylinder radius="0.15" length="0.1"/></geometry>\n      <material name="base_grey"/>'
BASE_COLLISION = '<collision name="base">\n      <origin xyz="0 0 0.05" rpy="0 0 0"/>\n      <geometry>'


def extra_visuals(*shapes: str) -> Callable[[str], str]:
    visuals = "".join(f"\n    </visual>\n    <visual><geometry>{shape}</geometry>" for shape in shapes)
    return lambda text: text.replace(BASE_VISUAL, BASE_VISUAL + visuals, 1)


def test_a_visual_without_area_draws_nothing_and_loads(tmp_path: Path) -> None:
    # pybullet's Laikago gives its toes visual spheres of radius 0 (their collision spheres 3 cm)
    nothing = ('<sphere radius="0.0"/>', '<box size="0 0 0.1"/>', '<cylinder radius="0" length="0.1"/>')
    flat = ('<box size="0.2 0.2 0"/>', '<cylinder radius="0.1" length="0"/>')  # a plate and a disc
    robot = ck.load_cpr(variant(tmp_path, extra_visuals(*nothing, *flat)))
    bundled = ck.load_cpr()
    assert robot.visual_model.ngeoms == bundled.visual_model.ngeoms + len(flat)  # those without area left out
    sides = [
        np.asarray(o.geometry.halfSide)
        for o in robot.visual_model.geometryObjects
        if hasattr(o.geometry, "halfSide")
    ]
    assert any(np.array_equal(side, [0.1, 0.1, 0.0]) for side in sides)
    assert robot.collision_model.ngeoms == bundled.collision_model.ngeoms
    visual_message = r"visual sphere radius = '-0.1' .* in \[0, 100\] m \(a visual may be flat\)$"
    with pytest.raises(ck.UrdfError, match=visual_message):
        ck.load_cpr(variant(tmp_path, extra_visuals('<sphere radius="-0.1"/>')))
    collision = BASE_COLLISION + '<cylinder radius="0.15"'
    zero_collision = BASE_COLLISION + '<cylinder radius="0"'
    with pytest.raises(ck.UrdfError, match=r"collision cylinder radius = '0' .* in \(0, 100\] m$"):
        ck.load_cpr(variant(tmp_path, lambda t: t.replace(collision, zero_collision)))


def test_a_moment_below_zero_by_rounding_loads(tmp_path: Path) -> None:
    # iCub's hip has ixx = -5.4e-20 kg m^2; Tiago's antenna an inertia that is not positive
    # semi-definite (not held): neither is a body the planner should refuse
    rounded = ck.load_cpr(variant(tmp_path, lambda t: t.replace('ixx="0.065"', 'ixx="-5e-13"', 1)))
    assert rounded.nq == ck.load_cpr().nq
    with pytest.raises(ck.UrdfError, match=r"ixx = -1e-09 kg m\^2 is below zero"):
        ck.load_cpr(variant(tmp_path, lambda t: t.replace('ixx="0.065"', 'ixx="-1e-9"', 1)))


def test_a_continuous_joint_is_planned_within_one_turn_either_way(tmp_path: Path) -> None:
    robot = ck.load_cpr(
        variant(
            tmp_path, lambda t: t.replace('name="theta1" type="revolute"', 'name="theta1" type="continuous"')
        )
    )
    assert (robot.limits.lower[0], robot.limits.upper[0]) == (-2 * math.pi, 2 * math.pi)
    assert robot.limits.velocity[0] == 1.5 and robot.nq == 5  # one coordinate, not cos/sin


def test_the_command_line_refuses_it_at_once_with_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    variant(tmp_path, theta1_limit("7", "1e12"))
    scene = tmp_path / "scene.yaml"
    scene.write_text("robot: robot.urdf\nstart: {tcp: [0.5, 0.45, 0.25]}\ngoal: {tcp: [-0.5, 0.45, 0.25]}\n")
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert "joint 'theta1' range [7, 1e+12] rad is not supported" in error and error.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_the_widest_supported_range_plans(tmp_path: Path) -> None:
    # one turn either way, written as a URDF usually does: loads and plans the paper case
    robot = ck.load_cpr(variant(tmp_path, theta1_limit("-6.2832", "6.2832")))
    assert robot.limits.upper[0] == pytest.approx(2 * math.pi, abs=1e-3)
    scene = dataclasses.replace(paper_scene(), duration=None, planner=PlannerSettings())
    result = plan(scene, robot)
    assert result.verification.accepted


@pytest.mark.parametrize(("lower", "upper"), [("-6.98132", "6.98132"), ("-1e12", "1e12"), ("-1", "1e9")])
def test_a_range_beyond_one_turn_is_planned_within_it(tmp_path: Path, lower: str, upper: str) -> None:
    # an industrial wrist's +-400 degrees, a URDF's "no limit": refused before ("range [-6.98132,
    # 6.98132] rad is not supported"); planned within its part of [-2 pi, 2 pi], and said so
    robot = ck.load_cpr(variant(tmp_path, theta1_limit(lower, upper)))
    expected = (max(float(lower), -2 * math.pi), min(float(upper), 2 * math.pi))
    assert (robot.limits.lower[0], robot.limits.upper[0]) == expected
    assert robot.ranges_narrowed == {"theta1": (float(lower), float(upper))}
    bundled = ck.load_cpr().limits
    assert np.array_equal(robot.limits.lower[1:], bundled.lower[1:])
    assert np.array_equal(robot.limits.upper[1:], bundled.upper[1:])
    scene = dataclasses.replace(paper_scene(), duration=None, planner=PlannerSettings())
    result = plan(scene, robot)
    assert result.verification.accepted
    q = result.trajectory(np.linspace(0.0, result.trajectory.duration, 200))
    assert np.all((q >= robot.limits.lower) & (q <= robot.limits.upper))
    assert f"The URDF's ranges of theta1 [{float(lower):.4g}, {float(upper):.4g}] rad pass one turn" in (
        "\n".join(limits_section(result))
    )


def test_robot_info_says_which_range_is_narrowed(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    urdf = variant(tmp_path, theta1_limit("-6.98132", "6.98132"))
    assert main(["robot-info", str(urdf), "--json"]) == 0
    joints = json.loads(capsys.readouterr().out)["joints"]
    assert joints[0]["urdf_range"] == [-6.98132, 6.98132] and joints[0]["upper"] == 2 * math.pi
    assert [j["urdf_range"] for j in joints[1:]] == [None] * 4
    assert main(["robot-info", str(urdf)]) == 0
    line = "theta1: [-6.283, 6.283] rad, 1.5, 3, 15 (the URDF's range [-6.981, 6.981] rad, planned within one"
    assert line in capsys.readouterr().out


def test_a_range_within_one_turn_as_written_is_not_narrowed(tmp_path: Path) -> None:
    # 6.2832 is 2 pi as a URDF writes it: within the tolerance, kept as the URDF gives it
    robot = ck.load_cpr(variant(tmp_path, theta1_limit("-6.2832", "6.2832")))
    assert robot.ranges_narrowed == {} and robot.limits.upper[0] == 6.2832


@pytest.mark.parametrize(
    ("width", "v", "a", "j"), [(5.8, 1.5, 3.0, 15.0), (0.01, 1.5, 3.0, 15.0), (2.0, 0.5, 2, 1e9)]
)
def test_crossing_time_is_the_trapezoid_plus_the_jerk_ramp(
    width: float, v: float, a: float, j: float
) -> None:
    cruise = width / v + v / a if width >= v * v / a else 2 * math.sqrt(width / a)
    assert crossing_time(width, v, a, j) == pytest.approx(cruise + a / j)
    # the bundled CPR's slowest joint crosses its range well within the bound
    robot = ck.load_cpr()
    limits = robot.limits
    longest = max(
        crossing_time(float(hi - lo), float(vv), float(aa), float(jj))
        for lo, hi, vv, aa, jj in zip(
            limits.lower, limits.upper, limits.velocity, limits.acceleration, limits.jerk, strict=True
        )
    )
    assert longest < MAX_CROSSING_S / 10


def test_a_urdf_the_parser_complains_about_loads_quietly(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    # urdfdom prints "Error: Material [...] color has no rgba" on fd 2 for a material without
    # a colour; the model builds, and the user's terminal stays quiet
    grey = '<material name="base_grey"><color rgba="0.35 0.35 0.38 1"/></material>'
    robot = ck.load_cpr(
        variant(tmp_path, lambda t: t.replace(grey, '<material name="base_grey"></material>'))
    )
    assert robot.joint_names == ck.CPR_JOINTS
    captured = capfd.readouterr()
    assert captured.err == "" and captured.out == ""


def test_a_urdf_pinocchio_refuses_names_its_words(tmp_path: Path) -> None:
    broken = variant(tmp_path, lambda t: t.replace('<robot name="cpr">', "<robot>"))
    with pytest.raises(ck.UrdfError, match=re.escape(str(broken))):
        ck.load_cpr(broken, validate=False)


def test_the_limits_file_rule_then_the_documented_defaults(tmp_path: Path) -> None:
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(URDF)
    effector = {"effector_links": ("wrist_link", "tool_link")}
    # no file beside it: every joint gets the defaults, and the robot says so
    robot = ck.load_robot(urdf, **effector)
    assert robot.limits_path is None and robot.limits_defaulted == ck.CPR_JOINTS
    np.testing.assert_allclose(robot.limits.acceleration, DEFAULT_ACCELERATION_PER_S * robot.limits.velocity)
    np.testing.assert_allclose(robot.limits.jerk, DEFAULT_JERK_PER_S * robot.limits.acceleration)
    # found beside the URDF: limits.yaml, then <stem>_limits.yaml before it
    for name in ("limits.yaml", "arm_limits.yaml"):
        (tmp_path / name).write_bytes(ck.cpr_limits_path().read_bytes())
        assert ck.load_robot(urdf, **effector).limits_path == tmp_path / name
    # a file that leaves a joint's jerk out: that joint alone is defaulted
    (tmp_path / "arm_limits.yaml").write_text(
        ck.cpr_limits_path()
        .read_text()
        .replace("jerk: 15.0", "velocity: 1.5")
        .replace(", velocity: 1.5}", "}")
    )
    partial = ck.load_robot(urdf, **effector)
    assert partial.limits_defaulted == ("theta1",) and partial.limits.jerk[1] == 10.0
    # the CPR preset falls back to the bundled limits
    alone = tmp_path / "alone"
    alone.mkdir()
    (alone / "cpr_variant.urdf").write_text(URDF)
    assert ck.load_cpr(alone / "cpr_variant.urdf").limits_path == ck.cpr_limits_path()


def test_the_report_states_default_limits(tmp_path: Path) -> None:
    from planning.io.report import report_markdown

    urdf = tmp_path / "arm.urdf"
    urdf.write_text(URDF)
    urdf.with_suffix(".srdf").write_bytes(
        ck.cpr_urdf_path().with_suffix(".srdf").read_bytes()
    )  # found beside
    robot = ck.load_robot(urdf, effector_links=("wrist_link", "tool_link"), wrist_joints=("theta4", "theta5"))
    scene = dataclasses.replace(paper_scene(), duration=None, planner=PlannerSettings())
    report = report_markdown(plan(scene, robot))
    assert "Acceleration and jerk limits of theta1, d2, d3, theta4, theta5 are the defaults" in report
    assert "no limits file" in report and "Held" not in report


def test_a_limit_without_lower_and_upper_is_the_specifications_zero_range(tmp_path: Path) -> None:
    # the URDF specification makes both optional (0 by default; urdfdom reads them so), where
    # yourdfpy's validation called the file invalid: Centauro's wheels load with its arm
    # (tests/test_urdf_models.py); a planned joint with that range is refused by name
    no_range = variant(tmp_path, lambda t: t.replace(THETA1, '<limit velocity="1.5" effort="100"/>'))
    with pytest.raises(
        ck.UrdfError, match=rf"joint 'theta1' range \[0, 0\] rad is not supported; {SUPPORTED}"
    ):
        ck.load_cpr(no_range, validate=True)


def test_a_pose_goal_across_a_continuous_joints_half_turn_is_reached_the_short_way() -> None:
    # Kinova's first joint is continuous: from 3.0 rad to a pose 0.3 rad further, across pi.
    # Planned within [-pi, pi], its IK solution's -2.98 rad could not be turned to 3.30 rad:
    # 5.3 s of motion, another elbow; now the joint turns 0.3 rad
    share = example_robot_data_share()
    assert share is not None
    robot = ck.load_robot(share / "example-robot-data/robots/kinova_description/robots/kinova.urdf")
    q_start = np.array([3.0, 2.9, 1.3, -2.0, 1.5, 0.5])
    q_across = q_start + np.array([0.3 - 2 * math.pi, 0, 0, 0, 0, 0])  # the same pose as 3.3 rad
    pose = ck.frame_poses(robot, q_across)
    goal = Target(pose=(tuple(pose[:3, 3]), tuple(map(tuple, pose[:3, :3]))))
    scene = Scene(robot=ck.robot_spec(robot.urdf_path), start=Target(q=tuple(q_start)), goal=goal)
    result = plan(scene, robot)
    assert result.verification.accepted
    q = result.trajectory(np.linspace(0.0, result.trajectory.duration, 400))
    assert np.ptp(q[:, 0]) == pytest.approx(0.3, abs=0.02)  # the short way: 0.3 rad, not 6
    reached = ck.frame_poses(robot, q[-1])
    np.testing.assert_allclose(reached, pose, atol=1e-3)  # the goal pose, by forward kinematics
