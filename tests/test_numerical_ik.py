"""The numerical IK on robots no one here wrote: round trips checked by yourdfpy's forward kinematics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yourdfpy

import cpr_kin as ck
from cpr_kin.certified.motion import path_weights
from cpr_kin.kinematics.numerical_ik import SAME_TIME_SHARE, about_seed, descent, soonest, tool_reach_m
from cpr_kin.model.packages import example_robot

ARMS = ("so101", "ur5", "panda", "xarm7")


@pytest.fixture(scope="module", params=ARMS)
def arm(request: pytest.FixtureRequest) -> tuple[ck.Robot, yourdfpy.URDF]:
    urdf: Path = example_robot(request.param)
    return ck.load_robot(urdf), yourdfpy.URDF.load(str(urdf), build_scene_graph=True, load_meshes=False)


def reference_tool_pose(robot: ck.Robot, reference: yourdfpy.URDF, q: np.ndarray) -> np.ndarray:
    """The tool frame's pose by yourdfpy, an independent URDF reader."""
    configuration = dict(zip(robot.joint_names, q, strict=True)) | dict(robot.held)
    reference.update_cfg({k: v for k, v in configuration.items() if k in reference.actuated_joint_names})
    return np.asarray(reference.get_transform(frame_to=robot.tcp_frame))


def rotation_error_rad(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(a.T @ b) - 1.0) / 2.0, -1.0, 1.0)))


@pytest.mark.parametrize("orientation", [True, False], ids=["pose", "position"])
def test_random_reachable_targets_round_trip(arm: tuple[ck.Robot, yourdfpy.URDF], orientation: bool) -> None:
    robot, reference = arm
    rng = np.random.default_rng(21)
    for q_true in rng.uniform(robot.limits.lower, robot.limits.upper, (6, robot.nq)):
        wanted = reference_tool_pose(robot, reference, q_true)
        target = ck.IkTarget(wanted[:3, 3], wanted[:3, :3] if orientation else None)
        q = ck.solve_ik(robot, target)  # from mid-range, not from q_true
        assert np.all(q >= robot.limits.lower) and np.all(q <= robot.limits.upper)
        reached = reference_tool_pose(robot, reference, q)
        assert np.linalg.norm(reached[:3, 3] - wanted[:3, 3]) <= target.tolerance_m
        if orientation:
            assert rotation_error_rad(reached[:3, :3], wanted[:3, :3]) <= target.tolerance_rad


def test_the_solution_nearest_the_seed_is_chosen(arm: tuple[ck.Robot, yourdfpy.URDF]) -> None:
    robot, reference = arm
    q_true = np.random.default_rng(5).uniform(robot.limits.lower, robot.limits.upper, robot.nq)
    wanted = reference_tool_pose(robot, reference, q_true)
    q = ck.solve_ik(robot, ck.IkTarget(wanted[:3, 3], wanted[:3, :3]), seed_q=q_true)
    np.testing.assert_allclose(q, q_true, atol=1e-9)  # the seed itself is a solution, at distance 0


def test_a_slow_joint_keeps_about_its_seed_value_where_the_fast_joints_reach_the_target(
    ur5_on_a_lift: ck.Robot,
) -> None:
    """Poses of configurations with the lift at the seed's height: reached about as soon as those.

    The configuration a target was made from is a solution the robot reaches in its move time
    from the seed (the oracle). The plain steps, which weigh a metre of the lift (0.02 m/s) as
    a radian of the arm's joints (3.2 rad/s), ended 6 of these 10 on solutions that moved the
    lift by 6-39 cm, up to 20 s against the arm's 2-4 s.
    """
    robot = ur5_on_a_lift
    lower, upper = robot.limits.lower, robot.limits.upper
    rng = np.random.default_rng(3)
    soon = 0
    for _ in range(10):
        seed, wanted = rng.uniform(lower, upper, (2, robot.nq))
        wanted[0] = seed[0]
        tool = ck.frame_poses(robot, wanted[None])[0]
        q = ck.solve_ik(robot, ck.IkTarget(tool[:3, 3], tool[:3, :3]), seed)
        soon += int(robot.limits.move_time_s(q - seed) <= 1.05 * robot.limits.move_time_s(wanted - seed))
    assert soon >= 8


def test_where_the_seeds_descent_least_in_time_misses_its_plain_descent_is_tried(
    ur5_on_a_lift: ck.Robot,
) -> None:
    robot = ur5_on_a_lift
    seed = np.array([0.356, 4.0511, -0.2515, -1.6816, 3.7935, 5.3222, -2.9389])
    wanted = np.array([0.2156, -0.7194, 5.4163, -2.8871, 2.9155, 1.4373, -5.9267])
    tool = ck.frame_poses(robot, wanted[None])[0]
    target = ck.IkTarget(tool[:3, 3], tool[:3, :3])
    only_the_seed = ck.IkSettings(restarts=0, more_restarts=0)
    free = np.ones(robot.nq, dtype=bool)
    scaled, _ = descent(robot, target, free, only_the_seed, robot.limits.speed_scales)(seed)
    assert not target.reached(pin.SE3(ck.frame_poses(robot, scaled[None])[0]))  # stalls
    q = ck.solve_ik(robot, target, seed, settings=only_the_seed)
    assert target.reached(pin.SE3(ck.frame_poses(robot, q[None])[0]))


def test_of_solutions_about_as_soon_the_nearest_in_robot_motion_is_chosen(ur5_on_a_lift: ck.Robot) -> None:
    robot = ur5_on_a_lift
    seed = (robot.limits.lower + robot.limits.upper) / 2
    lift, pan, wrist = (seed + np.eye(robot.nq)[j] * change for j, change in ((0, 0.1), (1, 1.0), (6, 1.02)))
    times_s = robot.limits.move_time_s(np.array([lift, pan, wrist]) - seed)
    assert times_s[0] > 5.0 and times_s[1] < times_s[2] < (1 + SAME_TIME_SHARE) * times_s[1]
    weights = path_weights(robot)  # robot motion: the last wrist's short lever, the lift's 10 cm, the pan
    assert weights @ np.abs(wrist - seed) < weights @ np.abs(lift - seed) < weights @ np.abs(pan - seed)
    assert soonest(robot, [lift, pan], seed) is pan  # soonest, though it sweeps more
    assert soonest(robot, [lift, pan, wrist], seed) is wrist  # about as soon, and nearer


def test_accepted_solutions_come_first() -> None:
    robot = ck.load_robot(example_robot("ur5"))
    seed = np.array([0.0, -1.2, 1.2, -1.0, 1.0, 0.0])
    tool = ck.frame_poses(robot, seed[None])[0]
    target = ck.IkTarget(tool[:3, 3])  # a position goal: the wrist is free to turn

    def wrist_up(q: np.ndarray) -> bool:
        return bool(q[3] > 0.5)

    assert not wrist_up(ck.solve_ik(robot, target, seed))  # the seed itself, nearest
    q = ck.solve_ik(robot, target, seed, accept=wrist_up)
    assert wrist_up(q)
    assert np.linalg.norm(ck.frame_poses(robot, q[None])[0][:3, 3] - tool[:3, 3]) <= target.tolerance_m


def test_preferred_solutions_come_first_among_the_accepted() -> None:
    """``prefer`` ranks the accepted solutions in the same search: with ``accept`` always true it
    gives what ``accept`` alone gives; where no accepted solution passes it, the nearest accepted
    one, asked of no solution ``accept`` refused."""
    robot = ck.load_robot(example_robot("ur5"))
    seed = np.array([0.0, -1.2, 1.2, -1.0, 1.0, 0.0])
    target = ck.IkTarget(ck.frame_poses(robot, seed[None])[0][:3, 3])

    def wrist_up(q: np.ndarray) -> bool:
        return bool(q[3] > 0.5)

    alone = ck.solve_ik(robot, target, seed, accept=wrist_up)
    ranked = ck.solve_ik(robot, target, seed, accept=lambda q: True, prefer=wrist_up)
    np.testing.assert_array_equal(ranked, alone)  # the same draws, the same choice
    asked: list[np.ndarray] = []

    def never(q: np.ndarray) -> bool:
        asked.append(q)
        return False

    fallback = ck.solve_ik(robot, target, seed, accept=wrist_up, prefer=never)
    assert wrist_up(fallback) and asked and all(wrist_up(q) for q in asked)
    assert any(np.array_equal(fallback, q) for q in asked)  # one of the accepted: the one reached soonest
    times = robot.limits.move_time_s(np.array(asked) - seed)
    soon = [q for q, t in zip(asked, times, strict=True) if t <= (1 + SAME_TIME_SHARE) * times.min()]
    weights = ck.path_weights(robot)  # of those about as soon, the nearest in robot motion
    assert float(weights @ np.abs(fallback - seed)) == min(float(weights @ np.abs(q - seed)) for q in soon)
    assert np.linalg.norm(ck.frame_poses(robot, fallback[None])[0][:3, 3] - target.position) <= 1e-4


def test_held_joints_stay_at_the_seed(robot: ck.Robot) -> None:
    seed = np.array([0.3, 0.2, 0.2, 0.4, -0.3])
    goal = ck.frame_poses(robot, np.array([[-0.5, 0.3, 0.35, 0.4, -0.3]]))[0][:3, 3]
    q = ck.solve_ik(robot, ck.IkTarget(goal), seed, held=("theta4", "theta5"))
    np.testing.assert_array_equal(q[3:], seed[3:])
    assert np.linalg.norm(ck.frame_poses(robot, q[None])[0][:3, 3] - goal) <= 1e-4


def test_a_target_out_of_reach_says_how_close_the_solver_came() -> None:
    robot = ck.load_robot(example_robot("panda"))
    with pytest.raises(
        ck.IkMissError,
        match=r"no configuration puts frame 'panda_hand_tcp' at \[1\.3, 0\.0, 0\.333\] m: the closest of 101 "
        r"IK starts came 0\.\d+ m from the position \(tolerance 0\.0001 m\)",
    ):
        ck.solve_ik(robot, ck.IkTarget(np.array([1.3, 0.0, 0.333])))  # within the bound, out of reach


@pytest.mark.parametrize("name", ["panda", "ur5", "so101", "z1"])
def test_the_reach_bound_holds_over_random_configurations(name: str) -> None:
    """An oracle: the tool's distance from the base at 20,000 random configurations (FK)."""
    robot = ck.load_robot(example_robot(name))
    lower, upper = robot.limits.lower, robot.limits.upper
    configurations = np.random.default_rng(2).uniform(lower, upper, (20_000, robot.nq))
    distances = np.linalg.norm(ck.frame_poses(robot, configurations)[:, :3, 3], axis=1)
    assert distances.max() <= tool_reach_m(robot)
    assert distances.max() >= 0.6 * tool_reach_m(robot)  # a bound, not a wild one


def test_the_reach_bound_counts_prismatic_travel(robot: ck.Robot) -> None:
    """The CPR's carriage and arm slide 0.6 and 0.5 m: its bound holds its sampled reach."""
    lower, upper = robot.limits.lower, robot.limits.upper
    configurations = np.random.default_rng(3).uniform(lower, upper, (20_000, robot.nq))
    distances = np.linalg.norm(ck.frame_poses(robot, configurations)[:, :3, 3], axis=1)
    without_travel = tool_reach_m(robot) - 0.6 - 0.5
    assert without_travel < distances.max() <= tool_reach_m(robot)


def test_a_start_that_makes_no_progress_ends_after_its_patience() -> None:
    robot = ck.load_robot(example_robot("ur5"))
    target = ck.IkTarget(np.array([1.25, 0.0, 0.3]))  # out of reach: the arm stretches, then stalls
    free = np.ones(robot.nq, dtype=bool)
    steps = {}
    for patience in (20, 1000):
        settings = ck.IkSettings(restarts=0, more_restarts=0, iterations=1000, patience=patience)
        with pytest.raises(ck.IkMissError, match=r"the closest of 1 IK starts came 0\.3"):
            ck.solve_ik(robot, target, settings=settings)
        mid_range = (robot.limits.lower + robot.limits.upper) / 2  # the start solve_ik takes first
        steps[patience] = descent(robot, target, free, settings)(mid_range)[1]
    assert 20 < steps[20] <= 100  # its patience ran out soon after the stretch
    assert steps[1000] == 1000  # without it, every step is taken


class CountedTarget(ck.IkTarget):
    """An IK target that counts how often its error is measured (once a start, at its end)."""

    steps = 0

    def excess(self, placement: pin.SE3) -> float:
        CountedTarget.steps += 1
        return super().excess(placement)


def test_a_target_beyond_the_reach_bound_is_refused_before_any_start() -> None:
    robot = ck.load_robot(example_robot("ur5"))
    CountedTarget.steps = 0
    with pytest.raises(
        ck.IkMissError,
        match=r"at \[5\.0, 0\.0, 0\.5\] m: it lies 5\.025 m from the robot's base, "
        r"beyond the 1\.329 m its links reach",
    ):
        ck.solve_ik(robot, CountedTarget(np.array([5.0, 0.0, 0.5])))
    assert CountedTarget.steps == 0


@pytest.mark.parametrize(
    ("changes", "pattern"),
    [
        ({"restarts": -1}, r"IkSettings\.restarts = -1 must be an integer in \[0, 100000\]"),
        ({"iterations": 2.5}, r"IkSettings\.iterations = 2\.5 must be an integer"),
        ({"damping": 0.0}, r"IkSettings\.damping = 0\.0 must be a number in \(0, 10\]"),
        ({"patience": 0}, r"IkSettings\.patience = 0 must be an integer in \[1, 100000\]"),
    ],
)
def test_bad_settings_are_refused(changes: dict[str, float], pattern: str) -> None:
    with pytest.raises(ck.CprKinError, match=pattern):
        ck.IkSettings(**changes)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("position", "rotation", "pattern"),
    [
        ([0.1, 0.2], None, r"must be three finite numbers"),
        ([0.1, np.nan, 0.2], None, r"must be three finite numbers"),
        ([0.1, 0.2, 0.3], np.ones((3, 3)), r"must be a 3 x 3 rotation matrix"),
    ],
)
def test_bad_targets_are_refused(position: list[float], rotation: np.ndarray | None, pattern: str) -> None:
    with pytest.raises(ck.CprKinError, match=pattern):
        ck.IkTarget(np.array(position), rotation)


def test_a_joint_a_turn_away_is_turned_towards_the_seed() -> None:
    """A UR5's joints span two turns (``[-2 pi, 2 pi]``): the same pose a turn apart. From a restart
    whose shoulder lies a turn from the seed's, the solution is turned back (yourdfpy's pose the
    same), and a turn that would leave the range is not made."""
    from cpr_kin.kinematics.numerical_ik import turned_towards

    robot = ck.load_robot(example_robot("ur5"))
    reference = yourdfpy.URDF.load(str(example_robot("ur5")), build_scene_graph=True, load_meshes=False)
    lower, upper = robot.limits.lower, robot.limits.upper
    revolute = np.ones(robot.nq, dtype=bool)
    q = np.array([0.3, 4.93, 1.87, -2.09, -1.57, -1.24])
    seed = np.array([5.6, -1.32, 1.83, -2.08, -1.57, 4.04])
    turned = turned_towards(q, seed, revolute, lower, upper)
    np.testing.assert_allclose(turned, [0.3, 4.93 - 2 * np.pi, 1.87, -2.09, -1.57, -1.24 + 2 * np.pi])
    np.testing.assert_allclose(  # the same pose
        reference_tool_pose(robot, reference, turned), reference_tool_pose(robot, reference, q), atol=1e-9
    )
    assert np.all(np.abs(turned - seed) <= np.abs(q - seed))  # no joint farther from the seed
    assert turned[0] == q[0]  # 0.3 + 2 pi would leave [-2 pi, 2 pi]
    np.testing.assert_array_equal(turned_towards(q, seed, ~revolute, lower, upper), q)  # prismatic: as is


def test_starts_of_a_joint_of_more_than_a_turn_are_drawn_within_the_turn_about_the_seed() -> None:
    # a UR's [-2 pi, 2 pi] joints, a continuous joint's: every pose lies within a turn of the seed
    lower = np.array([-2 * np.pi, -2 * np.pi, -2.9, 0.0])
    upper = np.array([2 * np.pi, 2 * np.pi, 2.9, 0.6])
    revolute = np.array([True, True, True, False])
    seed = np.array([5.5, -0.3, 2.0, 0.3])
    low, high = about_seed(seed, lower, upper, revolute)
    np.testing.assert_allclose(low, [0.0, -0.3 - np.pi, -2.9, 0.0])  # near the limit: shifted, not cut
    np.testing.assert_allclose(high, [2 * np.pi, -0.3 + np.pi, 2.9, 0.6])
    np.testing.assert_allclose((high - low)[:2], 2 * np.pi)  # a whole turn, within the range
    assert np.all((low >= lower) & (high <= upper) & (low <= seed) & (seed <= high))
