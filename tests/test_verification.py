from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.io.bundled import paper_scene
from planning.planner import PlanResult, plan
from planning.verification import verify_trajectory


@pytest.fixture(scope="module")
def result(robot: ck.Robot) -> PlanResult:
    return plan(paper_scene(3), robot)


def test_planned_trajectory_is_accepted(result: PlanResult, paper_world: ck.CollisionWorld) -> None:
    ends = (result.waypoints[0], result.waypoints[-1])
    verification = verify_trajectory(paper_world, result.trajectory, 0.1, 0.005, ends)
    assert verification.accepted and verification.problems == ()
    assert verification.check.certified_min_m == pytest.approx(result.metrics.min_clearance_m)


def test_each_violation_is_named(result: PlanResult, paper_world: ck.CollisionWorld) -> None:
    fast = result.trajectory.time_scaled(0.3)  # velocity x 3.3, acceleration x 11, jerk x 37
    wrong_ends = (result.waypoints[0] + np.array([0.1, 0, 0, 0, 0]), result.waypoints[-1])
    verification = verify_trajectory(paper_world, fast, 0.2, 0.005, wrong_ends)
    text = " | ".join(verification.problems)
    assert not verification.accepted
    assert "its start is 0.1 away from the scene's start" in text
    assert "certified) of an obstacle, margin 0.2 m" in text
    assert "drives the velocity of joint" in text and "drives the jerk of joint" in text
