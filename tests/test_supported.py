"""What the planner supports of a URDF: absurd joints are refused at load, naming the joint."""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Callable
from pathlib import Path

import pytest

import cpr_kin as ck
from cpr_kin.supported import MAX_CROSSING_S, crossing_time
from planning import PlannerSettings, paper_scene, plan
from planning.cli import main

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


SUPPORTED = r"the planner supports lower < upper within \[-6.2832, 6.2832\] rad"
REFUSED = [
    ("range 1e3", theta1_limit("-1000", "1000"),
     r"joint 'theta1' range \[-1000, 1000\] rad is not supported; " + SUPPORTED),
    ("range 1e12", theta1_limit("-1e12", "1e12"), r"'theta1' range \[-1e\+12, 1e\+12\] rad is not supported"),
    ("empty range", theta1_limit("0.5", "0.5"), r"joint 'theta1' range \[0.5, 0.5\] rad is not supported"),
    ("slow joint", theta1_limit("-2.9", "2.9", "1e-6"),
     r"joint 'theta1' needs 5.8e\+06 s to cross its range .* at most 600 s: raise the limits"),
    ("continuous", lambda t: t.replace('name="theta1" type="revolute"', 'name="theta1" type="continuous"'),
     r"joint 'theta1' is continuous \(it turns without end\); the planner needs a bounded range: "
     r"write it as type=\"revolute\""),
    ("planar", lambda t: t.replace('name="d2" type="prismatic"', 'name="d2" type="planar"'),
     r"joint 'd2' is of type 'planar'; supported: \['revolute', 'prismatic', 'fixed'\]"),
    ("mimic", lambda t: t.replace('<joint name="theta5" type="revolute">',
                                  '<joint name="theta5" type="revolute"><mimic joint="theta4"/>'),
     r"joint 'theta5' mimics another"),
    ("zero axis", lambda t: t.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1),
     r"joint 'theta1' axis xyz = '0 0 0' is not a direction"),
    ("bidirectional name", lambda t: t.replace('"d2"', '"d\u202e2"'),
     r"the joint name 'd\\u202e2' holds U\+202E \(RIGHT-TO-LEFT OVERRIDE\)"),
    ("control character", lambda t: t.replace('link name="tcp"', 'link name="t\x85cp"'),
     r"the link name 't\\x85cp' holds U\+0085"),
]  # fmt: skip


@pytest.mark.parametrize(("label", "edit", "message"), REFUSED, ids=[case[0] for case in REFUSED])
def test_an_unsupported_urdf_is_refused_at_load_naming_the_joint(
    tmp_path: Path, label: str, edit: Callable[[str], str], message: str
) -> None:
    with pytest.raises(ck.UrdfError, match=message):
        ck.load_cpr(variant(tmp_path, edit))


def test_the_command_line_refuses_it_at_once_with_exit_2(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    variant(tmp_path, theta1_limit("-1e12", "1e12"))
    scene = tmp_path / "scene.yaml"
    scene.write_text("robot: robot.urdf\nstart: {tcp: [0.5, 0.45, 0.25]}\ngoal: {tcp: [-0.5, 0.45, 0.25]}\n")
    assert main(["plan", str(scene), "--out", str(tmp_path / "out")]) == 2
    error = capsys.readouterr().err
    assert "joint 'theta1' range [-1e+12, 1e+12] rad is not supported" in error and error.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_the_widest_supported_range_plans(tmp_path: Path) -> None:
    # one turn either way, written as a URDF usually does: loads and plans the paper case
    robot = ck.load_cpr(variant(tmp_path, theta1_limit("-6.2832", "6.2832")))
    assert robot.limits.upper[0] == pytest.approx(2 * math.pi, abs=1e-3)
    scene = dataclasses.replace(paper_scene(), duration=None, planner=PlannerSettings())
    result = plan(scene, robot)
    assert result.verification.accepted


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


def test_the_limits_file_rule_names_every_path_it_looked_for(tmp_path: Path) -> None:
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(URDF)
    with pytest.raises(ck.UrdfError) as refused:
        ck.load_robot(urdf, effector_links=("wrist_link", "tool_link"))
    looked = [tmp_path / "arm_limits.yaml", tmp_path / "limits.yaml"]
    assert all(f"'{path}'" in str(refused.value) for path in looked)
    # found beside the URDF by the first name, then the second; the CPR preset falls back
    for name in ("limits.yaml", "arm_limits.yaml"):
        (tmp_path / name).write_bytes(ck.cpr_limits_path().read_bytes())
        assert ck.load_robot(urdf, effector_links=("wrist_link", "tool_link")).limits_path == tmp_path / name
    alone = tmp_path / "alone"
    alone.mkdir()
    (alone / "cpr_variant.urdf").write_text(URDF)
    assert ck.load_cpr(alone / "cpr_variant.urdf").limits_path == ck.cpr_limits_path()
