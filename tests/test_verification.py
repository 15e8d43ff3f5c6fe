from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.io.bundled import paper_scene
from planning.pipeline.planner import plan
from planning.pipeline.result import PlanResult
from planning.pipeline.target import Target
from planning.pipeline.verification import STOPPED, Requirements, verify_for_scene, verify_trajectory


@pytest.fixture(scope="module")
def result(robot: ck.Robot) -> PlanResult:
    return plan(paper_scene(3), robot)


def test_planned_trajectory_is_accepted(result: PlanResult, paper_world: ck.CollisionWorld) -> None:
    ends = (Target(q=tuple(result.waypoints[0])), Target(q=tuple(result.waypoints[-1])))
    verification = verify_trajectory(paper_world, result.trajectory, Requirements(0.1, 0.005, endpoints=ends))
    assert verification.accepted and verification.problems == ()
    assert verification.check.certified_min_m == pytest.approx(result.metrics.min_clearance_m)


def test_a_verification_stopped_before_its_verdict_accepts_nothing(
    result: PlanResult, paper_world: ck.CollisionWorld
) -> None:
    required = Requirements(0.1, 0.005)
    asked: list[int] = []

    def never() -> bool:
        asked.append(1)
        return False

    kept = verify_trajectory(paper_world, result.trajectory, required, stop=never)
    assert kept.accepted and asked  # asked, never stopped: the verdict of a check without a stop
    assert (
        kept.check.certified_min_m
        == verify_trajectory(paper_world, result.trajectory, required).check.certified_min_m
    )
    stopped = verify_trajectory(paper_world, result.trajectory, required, stop=lambda: True)
    assert not stopped.accepted and stopped.problems == (STOPPED,)
    assert stopped.check.certified_min_m == -np.inf and not stopped.check.accepted


def test_a_file_in_another_joint_order_is_refused_by_name(result: PlanResult) -> None:
    names = list(result.problem.robot.joint_names)
    assert not verify_for_scene(result.problem, result.trajectory, names).problems
    swapped = [names[1], names[0], *names[2:]]
    named = f"trajectory joints \\['{names[1]}', '{names[0]}'.*are not the robot's"
    with pytest.raises(PlanningError, match=named):
        verify_for_scene(result.problem, result.trajectory, swapped)


def test_each_violation_is_named(result: PlanResult, paper_world: ck.CollisionWorld) -> None:
    fast = result.trajectory.time_scaled(0.3)  # velocity x 3.3, acceleration x 11, jerk x 37
    shifted = result.waypoints[0] + np.array([0.1, 0, 0, 0, 0])
    wrong_ends = (Target(q=tuple(shifted)), Target(q=tuple(result.waypoints[-1])))
    verification = verify_trajectory(paper_world, fast, Requirements(0.2, 0.005, endpoints=wrong_ends))
    text = " | ".join(verification.problems)
    assert not verification.accepted
    assert (
        "its start is 0.1 rad from the value of joint 'theta1' (tolerance 1e-06 rad) of the scene's start"
        in text
    )
    assert "certified) of an obstacle, margin 0.2 m" in text
    assert "drives the velocity of joint" in text and "drives the jerk of joint" in text


@pytest.mark.parametrize(("order", "unit"), [(0, "rad"), (1, "rad/s"), (2, "rad/s^2"), (3, "rad/s^3")])
def test_a_jump_at_a_knot_is_named(
    result: PlanResult, paper_world: ck.CollisionWorld, order: int, unit: str
) -> None:
    # shift one coefficient of the last segment's theta1: its value, or a derivative, jumps
    # at the segment's start (knot 3) and nowhere else
    coefficients = result.trajectory.coefficients.copy()
    coefficients[3, 0, order] += 0.3 / math.factorial(order)
    broken = Trajectory(result.trajectory.knots, coefficients)
    problems = verify_trajectory(paper_world, broken, Requirements(0.1, 0.005)).problems
    name = ("position", "velocity", "acceleration", "jerk")[order]
    assert (
        f"is not continuous (C3) at t = 3 s (knot 3): the {name} of joint 'theta1' jumps by 0.3 {unit}"
        in problems
    )


def test_rounding_at_a_knot_where_the_robot_rests_is_not_a_jump(
    result: PlanResult, paper_world: ck.CollisionWorld
) -> None:
    # a rest-to-rest septic move of theta1, then two segments holding its end (a stop-and-go
    # trajectory rests so at its vertices): between the holds every local magnitude
    # vanishes, and a jerk of 2e-6 rad/s^3 there is rounding against the move's peak jerk
    # (26.25 rad/s^3), not a break
    coefficients = np.zeros((3, 5, 8))
    coefficients[:, :, 0] = result.waypoints[0]
    coefficients[0, 0, 4:] = 0.5 * np.array([35.0, -84.0, 70.0, -20.0])  # zero v, a, j at both ends
    coefficients[1:, 0, 0] += 0.5
    coefficients[2, 0, 3] = 2e-6 / 6
    knots = np.array([0.0, 1.0, 2.0, 3.0])
    requirements = Requirements(0.1, 0.005)
    rested = Trajectory(knots, coefficients)
    assert rested.extrema(3).peak[0] == pytest.approx(26.25)
    assert not any("continuous" in p for p in verify_trajectory(paper_world, rested, requirements).problems)
    coefficients[2, 0, 3] = 4e-4 / 6  # beyond rounding: 15e-6 of the peak
    problems = verify_trajectory(paper_world, Trajectory(knots, coefficients), requirements).problems
    assert any("(knot 2): the jerk of joint 'theta1' jumps by 0.0004 rad/s^3" in p for p in problems)


def test_knot_jumps_agree_with_evaluation_and_vanish_for_the_planned_spline(result: PlanResult) -> None:
    trajectory = result.trajectory
    jump, relative = trajectory.knot_jumps(4)
    assert relative.max() < 1e-11  # a C3 spline: rounding only
    coefficients = trajectory.coefficients.copy()
    coefficients[1, 2, 1] += 0.25  # d2's velocity at the start of segment 1
    jump, _ = Trajectory(trajectory.knots, coefficients).knot_jumps(4)
    t = trajectory.knots[1]
    left, right = trajectory(t - 1e-12, 1), Trajectory(trajectory.knots, coefficients)(t, 1)
    assert jump[0, 2, 1] == pytest.approx(abs(left[2] - right[2]), abs=1e-9) == pytest.approx(0.25)


@pytest.mark.slow
def test_check_certifies_what_the_planner_certified_at_its_finer_self_step(tmp_path: Path) -> None:
    """MotionBenchMaker's UR5 table_under_pick_0062 (vamp-planner's problems, from PyPI, cached).

    Its grasp holds the wrist within a millimetre of the forearm: the planner certifies the
    self-clearance at the finer step (:func:`~planning.pipeline.problem.finer_step_m`), and
    ``cpr-plan check``, reading the file back onto a problem built anew, must too, not only
    the obstacle clearance.
    """
    from planning.bench.mbm import import_problem, problems
    from planning.io.scene_file import load_scene
    from planning.io.trajectory_io import write_trajectory
    from planning.io.trajectory_reader import read_trajectory
    from planning.pipeline.problem import build_problem
    from planning.pipeline.verification import verify_for_scene

    problem = next(p for p in problems("ur5", ("table_under_pick",)) if p.index == 62)
    scene = load_scene(import_problem(problem, tmp_path / "table_under_pick_0062.yaml"))
    result = plan(scene)
    assert result.verification.accepted
    path = tmp_path / "trajectory.json"
    write_trajectory(result, path)
    fresh = build_problem(scene)
    assert verify_for_scene(fresh, read_trajectory(path).trajectory).problems == ()
