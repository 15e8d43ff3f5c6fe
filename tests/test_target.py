"""Starts and goals: joint vectors, positions and poses, every IK result verified by forward kinematics."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning import PlanningError, Target
from tests.conftest import PAPER_START_TCP


def tool_position(robot: ck.Robot, q: np.ndarray) -> np.ndarray:
    return np.asarray(ck.frame_poses(robot, np.asarray(q)[None])[0][:3, 3])


@pytest.fixture(scope="module")
def tilted_cpr(tmp_path_factory: pytest.TempPathFactory) -> ck.Robot:
    """A CPR variant whose arm slides 6 degrees off the horizontal: the analytic IK does not model it."""
    text = ck.load_cpr().urdf_path.read_text()
    d3 = text.index('<joint name="d3"')
    axis = text.index('<axis xyz="1 0 0"/>', d3)
    tilted = text[:axis] + '<axis xyz="0.9945 0 0.1045"/>' + text[axis + len('<axis xyz="1 0 0"/>') :]
    folder = tmp_path_factory.mktemp("tilted")
    (folder / "cpr.urdf").write_text(tilted)
    return ck.load_cpr(folder / "cpr.urdf")


def test_the_cprs_analytic_ik_is_used_and_verified(robot: ck.Robot) -> None:
    target = Target(tcp=PAPER_START_TCP, hold={"theta4": 0.3, "theta5": -0.2})
    q = target.configuration(robot)
    np.testing.assert_array_equal(q, ck.tcp_ik(robot, PAPER_START_TCP, 0.3, -0.2))
    assert target.miss(robot, q) is None
    assert np.linalg.norm(tool_position(robot, q) - PAPER_START_TCP) < 1e-9


def test_a_variant_the_analytic_ik_misses_is_solved_numerically(tilted_cpr: ck.Robot) -> None:
    goal = (0.45, 0.35, 0.3)
    target = Target(tcp=goal, hold={"theta4": 0.2, "theta5": 0.1})
    analytic = ck.tcp_ik(tilted_cpr, goal, 0.2, 0.1)
    miss = target.miss(tilted_cpr, analytic)
    assert miss is not None and "m from the position" in miss  # the analytic answer is millimetres off
    q = target.configuration(tilted_cpr)
    assert target.miss(tilted_cpr, q) is None
    assert np.linalg.norm(tool_position(tilted_cpr, q) - goal) <= target.tolerance_m
    np.testing.assert_array_equal(q[3:], [0.2, 0.1])  # the wrist angles are held


def test_a_tcp_the_variant_cannot_reach_names_both_answers(tilted_cpr: ck.Robot) -> None:
    with pytest.raises(ck.IkMissError, match=r"came .* m from the position .*; the robot's analytic IK: "):
        Target(tcp=(1.6, 0.0, 0.3)).configuration(tilted_cpr)  # within the reach bound, out of reach
    with pytest.raises(ck.IkMissError, match=r"beyond the 1\.8 m its links reach; the robot's analytic IK: "):
        Target(tcp=(3.0, 0.0, 0.3)).configuration(tilted_cpr)


def test_a_joint_map_is_a_joint_vector(robot: ck.Robot) -> None:
    values = (0.1, 0.2, 0.3, 0.4, 0.5)
    by_name = Target(q=dict(zip(robot.joint_names, values, strict=True)))
    np.testing.assert_array_equal(by_name.configuration(robot), values)
    assert Target(q=values).miss(robot, np.array(values)) is None
    # the joint farthest from its value named, with its unit
    assert by_name.miss(robot, np.array([0.1, 0.2, 0.3, 0.4, 0.6])) == (
        f"0.1 rad from the value of joint '{robot.joint_names[4]}' (tolerance 1e-06 rad)"
    )
    assert by_name.miss(robot, np.array([0.1, 0.25, 0.3, 0.4, 0.5])) == (
        f"0.05 m from the value of joint '{robot.joint_names[1]}' (tolerance 1e-06 m)"
    )


def test_a_pose_goal_is_met_within_its_tolerances() -> None:
    panda = ck.load_robot(example_robot("panda"))
    q_true = np.array([0.3, -0.4, 0.2, -2.0, 0.1, 1.8, 0.5])
    tool = ck.frame_poses(panda, q_true[None])[0]
    position = tuple(tool[:3, 3])
    rotation = tuple(tuple(row) for row in tool[:3, :3])
    target = Target(pose=(position, rotation), tolerance_m=1e-5, tolerance_rad=1e-4)
    q = target.configuration(panda, seed_q=np.zeros(7))
    assert target.miss(panda, q) is None
    turned = q.copy()
    turned[6] += 0.01  # the last joint turns the hand about the tool axis: same position, other orientation
    miss = target.miss(panda, turned)
    assert (
        miss is not None
        and "rad from the orientation (tolerance 0.0001 rad) of frame 'panda_hand_tcp'" in miss
    )


def test_a_held_joint_the_robot_does_not_plan_is_refused() -> None:
    ur5 = ck.load_robot(example_robot("ur5"))
    with pytest.raises(PlanningError, match=r"hold = \{'theta4': 0.5\}: \['theta4'\] not planned joint\(s\)"):
        Target(tcp=(0.4, 0.1, 0.4), hold={"theta4": 0.5}).configuration(ur5)
    with pytest.raises(PlanningError, match="joints are held with a 'tcp' target only"):
        Target(q=(0.0,) * 6, hold={"wrist_3_joint": 0.5})


def test_any_robot_holds_the_joints_a_tcp_target_names(robot: ck.Robot) -> None:
    # the numerical IK holds a UR5's last joint where the target says; the CPR's analytic IK its wrist
    ur5 = ck.load_robot(example_robot("ur5"))
    target = Target(tcp=(0.4, 0.1, 0.4), hold={"wrist_3_joint": 0.7, "wrist_1_joint": -1.2})
    q = target.configuration(ur5)
    assert target.miss(ur5, q) is None
    assert q[ur5.limits.index("wrist_3_joint")] == pytest.approx(0.7, abs=1e-9)
    assert q[ur5.limits.index("wrist_1_joint")] == pytest.approx(-1.2, abs=1e-9)
    assert np.linalg.norm(tool_position(ur5, q) - (0.4, 0.1, 0.4)) <= target.tolerance_m
    moved = q.copy()
    moved[ur5.limits.index("wrist_3_joint")] += 0.01  # the position is kept (the last joint spins the tool)
    assert "held joints are off their values by {'wrist_3_joint': 0.01}" in (target.miss(ur5, moved) or "")
    with pytest.raises(ck.JointLimitError, match=r"joint 'theta4' = 9 rad is outside"):
        Target(tcp=PAPER_START_TCP, hold={"theta4": 9.0}).configuration(robot)


@pytest.mark.parametrize(
    ("fields", "pattern"),
    [
        ({}, r"exactly one of 'q' \(joint values\), 'tcp' \(x, y, z\), 'pose': \[\]"),
        ({"q": (0.0,) * 5, "tcp": (0.5, 0.0, 0.3)}, r"exactly one of .*: \['tcp', 'q'\]"),
        ({"tcp": (0.5, 0.0, 0.3), "tolerance_m": 0.0}, r"tolerances 0.0 m, 0.001 rad must be > 0"),
    ],
)
def test_bad_targets_are_refused(fields: dict[str, object], pattern: str) -> None:
    with pytest.raises(PlanningError, match=pattern):
        Target(**fields)  # type: ignore[arg-type]
