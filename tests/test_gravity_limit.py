"""Paths the motors can hold still: the gravity limit of arms whose shoulders gravity can overpower."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot, example_robot_data_share
from planning.bench.arm_scenes import blocked_scene
from planning.io.scene_file import parse_scene
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem, with_planner
from planning.pipeline.seeding import PathSeeding
from planning.pipeline.torques import GravityLimit, gravity_limit, torque_profile
from planning.pipeline.tuning import SearchTuning, SeedingTuning

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
ROBOTS = SHARE / "example-robot-data" / "robots"
TALOS = ROBOTS / "talos_data" / "robots" / "talos_left_arm.urdf"
TALOS_TOOL = "gripper_left_base_link"


@pytest.fixture(scope="module")
def talos() -> ck.Robot:
    # its shoulder's effort limit (22.3 N m) holds a fifth of the arm's configurations no longer
    return ck.load_robot(TALOS, tcp=TALOS_TOOL)


def limit_of(robot: ck.Robot) -> GravityLimit | None:
    middle = (robot.limits.lower + robot.limits.upper) / 2
    return gravity_limit(robot, ck.robot_dynamics(robot), middle, np.arange(robot.nq))


@pytest.fixture(scope="module")
def talos_limit(talos: ck.Robot) -> GravityLimit:
    limit = limit_of(talos)
    assert limit is not None
    return limit


def drawn(robot: ck.Robot, seed: int, count: int) -> np.ndarray:
    """``count`` seeded configurations of ``robot`` over its ranges."""
    return np.random.default_rng(seed).uniform(robot.limits.lower, robot.limits.upper, (count, robot.nq))


def test_the_limit_binds_only_where_gravity_can_exceed_an_effort(talos: ck.Robot) -> None:
    assert limit_of(talos) is not None
    assert limit_of(ck.load_cpr()) is None  # gravity needs at most a fifth of its efforts
    assert limit_of(ck.load_robot(example_robot("ur5"))) is None


def test_held_configurations_are_those_whose_gravity_torques_pinocchio_finds_within_the_efforts(
    talos: ck.Robot, talos_limit: GravityLimit
) -> None:
    limit, q = talos_limit, drawn(talos, 3, 200)
    model = limit.dynamics.model
    data = model.createData()
    gravity = np.array([pin.computeGeneralizedGravity(model, data, qi) for qi in q])  # the oracle
    usage = np.max(np.abs(gravity) / limit.dynamics.effort, axis=1)
    np.testing.assert_allclose(limit.usage(q), usage, rtol=1e-9)
    np.testing.assert_array_equal(limit.holds(q), usage <= 1.0)
    assert 0 < np.count_nonzero(usage > 1.0) < len(q)  # both kinds drawn


def test_a_path_through_a_configuration_it_cannot_hold_exceeds_by_its_worst_checked_sample(
    talos: ck.Robot, talos_limit: GravityLimit
) -> None:
    limit, q = talos_limit, drawn(talos, 4, 400)
    usage = limit.usage(q)
    held, dropped = q[usage < 0.5][:2], q[usage > 1.1][0]
    path = np.linspace(held[0], held[1], 9)  # samples 0, 4 and 8 are checked
    through = path.copy()
    through[4] = dropped
    excess = limit.path_excess(np.stack([path, through]))
    assert excess[1] == pytest.approx(max(limit.usage(through[[0, 4, 8]])) - 1.0)
    assert excess[0] == pytest.approx(max(limit.usage(path[[0, 4, 8]]).max() - 1.0, 0.0))


@pytest.mark.parametrize("seed", [602, 603])
def test_a_way_around_the_ball_keeps_the_shoulder_within_its_effort(talos: ck.Robot, seed: int) -> None:
    # RRT-Connect's path and the search's spline once swung the arm where gravity alone needed
    # 1.29-1.34x the shoulder's effort: no timing runs that, and the plan said "no solution"
    entry = {"urdf": str(TALOS), "tcp": TALOS_TOOL}
    scene = parse_scene(blocked_scene(f"talos_{seed}", entry, talos, seed, self_clearance_m=0.015))
    problem = build_problem(scene, talos)
    assert problem.gravity is not None
    result = plan(scene, talos)
    assert result.verification.accepted
    assert result.breakdown.holding_excess.max() == 0.0
    times = np.linspace(0.0, result.trajectory.duration, 400)
    assert problem.gravity.holds(result.trajectory(times)).all()
    assert torque_profile(problem.dynamics, result.trajectory).peak_utilisation.max() <= 1.0 + 1e-9


def test_no_path_names_the_rule_it_kept(talos: ck.Robot) -> None:
    entry = {"urdf": str(TALOS), "tcp": TALOS_TOOL}
    scene = parse_scene(blocked_scene("talos_602", entry, talos, 602, self_clearance_m=0.015))
    problem = build_problem(scene, talos)
    one_sample = with_planner(problem, tuning=SearchTuning(seeding=SeedingTuning(max_samples=1)))
    attempt = PathSeeding().first(one_sample)
    assert attempt.no_path
    assert attempt.tried.endswith("in 1 samples through configurations the motors can hold still")


def test_a_goal_pose_takes_an_ik_solution_the_motors_can_hold() -> None:
    # the PR2's right arm, scene 700: the clear solution nearest the start needs 38.4 N m of
    # the shoulder lift (30 N m); another one of the same pose needs less
    pr2_description = ROBOTS / "pr2_description"
    entry = {"urdf": str(pr2_description / "urdf" / "pr2.urdf"), "tcp": "r_gripper_tool_frame"}
    pr2 = ck.load_robot(entry["urdf"], tcp=entry["tcp"])
    scene = parse_scene(blocked_scene("pr2_700", entry, pr2, 700, self_clearance_m=0.015))
    problem = build_problem(scene, pr2)
    holding = problem.dynamics.torques(problem.q_goal)[0]
    assert np.all(np.abs(holding) <= problem.dynamics.effort)
    assert scene.goal.miss(pr2, problem.q_goal) is None  # and it reaches the pose
