from __future__ import annotations

import math

import numpy as np
import pytest

import cpr_kin as ck

from .conftest import PAPER_GOAL_TCP, PAPER_START_TCP, random_configurations


def test_paper_start_and_goal(robot: ck.Robot) -> None:
    start = ck.tcp_ik(robot, PAPER_START_TCP)
    goal = ck.tcp_ik(robot, PAPER_GOAL_TCP)
    r_f = math.hypot(0.5, 0.45)
    np.testing.assert_allclose(start, [math.atan2(0.45, 0.5), 0.15, r_f - 0.30, 0, 0], atol=1e-12)
    np.testing.assert_allclose(goal, [math.atan2(0.45, -0.5), 0.15, r_f - 0.30, 0, 0], atol=1e-12)


@pytest.mark.parametrize("wrist", [(0.0, 0.0), (0.7, -0.4), (-2.0, 1.2)])
def test_round_trip(robot: ck.Robot, rng: np.random.Generator, wrist: tuple[float, float]) -> None:
    configurations = random_configurations(robot, rng, 200)
    configurations[:, 3:] = wrist
    targets = ck.frame_positions(robot, configurations)
    for q, target in zip(configurations, targets, strict=True):
        solution = ck.tcp_ik(robot, target, *wrist)
        np.testing.assert_allclose(ck.frame_positions(robot, solution), target, atol=1e-12)
        # the CPR's inverse kinematics is unique within the joint limits
        np.testing.assert_allclose(solution, q, atol=1e-9)


@pytest.mark.parametrize(
    ("target", "pattern"),
    [
        ((1.0, 0.0, 0.3), r"joint 'd3' = 0\.7 m is outside \[0, 0\.5\] m"),
        ((0.1, 0.0, 0.3), r"joint 'd3' = -0\.2 m is outside \[0, 0\.5\] m"),
        ((0.5, 0.0, 0.9), r"joint 'd2' = 0\.8 m is outside \[0, 0\.6\] m"),
        ((-0.5, -0.05, 0.3), r"joint 'theta1' = -3\.04\d* rad is outside \[-2\.9, 2\.9\] rad"),
    ],
)
def test_out_of_reach_names_the_joint(
    robot: ck.Robot, target: tuple[float, float, float], pattern: str
) -> None:
    with pytest.raises(ck.UnreachableError, match=pattern) as info:
        ck.tcp_ik(robot, target)
    assert str(list(target)) in str(info.value)


@pytest.mark.parametrize("target", [(0.5, math.nan, 0.3), (0.5, 0.3), "here"])
def test_bad_target(robot: ck.Robot, target: object) -> None:
    with pytest.raises(ck.CprKinError, match="TCP target"):
        ck.tcp_ik(robot, target)  # type: ignore[arg-type]


def test_wrist_outside_limits(robot: ck.Robot) -> None:
    with pytest.raises(ck.JointLimitError, match=r"joint 'theta5' = 2 rad is outside \[-1\.6, 1\.6\] rad"):
        ck.tcp_ik(robot, PAPER_START_TCP, theta5=2.0)
