"""A robot against itself: the pairs checked, the SRDF, and a certificate no denser sampling beats."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.bounds.reach import geometry_reach, relative_radii
from cpr_kin.certified.self_curve import check_self_curve
from cpr_kin.collision.robot_reach import robot_reach
from cpr_kin.collision.self_collision import SelfCollision
from cpr_kin.collision.srdf_pairs import read_srdf, self_pairs
from cpr_kin.model.packages import example_robot_data_share
from planning import Scene, Target, plan
from planning.bench.mbm import vamp_resources
from planning.errors import PlanningError
from planning.pipeline.problem import build_problem, with_planner
from planning.pipeline.settings import PlannerSettings

from .conftest import after_calls

SHARE = example_robot_data_share()
assert SHARE is not None, "example-robot-data is part of the robots extra, which make installs"
PANDA = SHARE / "example-robot-data" / "robots" / "panda_description" / "urdf" / "panda.urdf"
BAXTER = SHARE / "example-robot-data" / "robots" / "baxter_description"


@pytest.fixture(scope="module")
def panda() -> ck.Robot:
    return ck.load_robot(PANDA)


def distances(robot: ck.Robot, q: np.ndarray, pairs: tuple[tuple[int, int], ...]) -> np.ndarray:
    names = [g.name for g in robot.geometries]
    return SelfCollision(robot.model, robot.collision_model, pairs, names).distances(q)[0]


def test_the_cpr_cannot_meet_itself(robot: ck.Robot) -> None:
    assert robot.self_pairs == () and robot.srdf_path == ck.cpr_urdf_path().with_suffix(".srdf")
    # without its SRDF: the ten non-adjacent pairs; the two it calls always touching do, and the
    # eight it calls never meeting stay centimetres apart over many configurations
    every = self_pairs(robot.model, robot.collision_model, frozenset())
    links = [g.link for g in robot.geometries]
    assert len(every) == 10
    disabled = read_srdf(robot.srdf_path, {f.name for f in robot.model.frames}).disabled
    assert {frozenset((links[a], links[b])) for a, b in every} == disabled
    q = np.random.default_rng(3).uniform(robot.limits.lower, robot.limits.upper, (5000, robot.nq))
    for a, b in every:
        pair = frozenset((links[a], links[b]))
        closest = distances(robot, q, ((a, b),)).min()
        if pair in (frozenset(("column_link", "arm_link")), frozenset(("arm_link", "tool_link"))):
            assert closest <= 0.0, pair
        else:
            assert closest > 0.05, pair


def test_the_srdf_skips_unknown_links_as_moveit_does_and_says_so(tmp_path: Path, robot: ck.Robot) -> None:
    links = {f.name for f in robot.model.frames}
    bad = tmp_path / "bad.srdf"
    bad.write_text(
        '<robot><disable_collisions link1="arm_link" link2="elbow"/>'
        '<disable_collisions link1="arm_link" link2="base_link"/></robot>'
    )
    pairs = read_srdf(bad, links)
    assert pairs.disabled == {frozenset(("arm_link", "base_link"))} and pairs.unknown_links == ("elbow",)
    loaded = dataclasses.replace(ck.cpr_spec(robot.urdf_path), srdf=bad).load()
    assert loaded.srdf_unknown_links == ("elbow",) and loaded.srdf_path == bad
    bad.write_text("<robot><disable_collisions")
    with pytest.raises(ck.UrdfError, match="is not well-formed XML"):
        read_srdf(bad, links)


def test_an_srdfs_default_entries_disable_a_links_pairs_but_those_enabled(tmp_path: Path) -> None:
    # srdfdom's <disable_default_collisions> and <enable_collisions> (MoveIt 2's setup assistant)
    links = {"base", "arm", "hand", "tool"}
    srdf = tmp_path / "defaults.srdf"
    srdf.write_text(
        '<robot><disable_default_collisions link="hand"/>'
        '<enable_collisions link1="hand" link2="base" reason="checked"/>'
        '<disable_collisions link1="arm" link2="tool"/><disable_default_collisions link="wheel"/></robot>'
    )
    pairs = read_srdf(srdf, links)
    expected = {frozenset(pair) for pair in [("hand", "arm"), ("hand", "tool"), ("arm", "tool")]}
    assert pairs.disabled == expected and pairs.unknown_links == ("wheel",)


def test_the_pandas_srdf_leaves_the_pairs_that_can_meet(panda: ck.Robot) -> None:
    assert panda.srdf_path is not None and panda.srdf_path.name == "panda.srdf"
    links = {frozenset((panda.geometries[a].link, panda.geometries[b].link)) for a, b in panda.self_pairs}
    assert frozenset(("panda_link1", "panda_link5")) in links  # a folded arm's elbow against its base
    assert frozenset(("panda_link6", "panda_link7")) not in links  # adjacent
    q = np.random.default_rng(0).uniform(panda.limits.lower, panda.limits.upper, (500, panda.nq))
    assert 0 < np.mean(ck.CollisionWorld(panda, []).self_collision.distances(q)[0] < 0) < 0.2


def random_curves(robot: ck.Robot, count: int, seed: int) -> list[tuple[np.ndarray, np.ndarray]]:
    rng = np.random.default_rng(seed)
    return [tuple(rng.uniform(robot.limits.lower, robot.limits.upper, (2, robot.nq))) for _ in range(count)]


def test_the_certificate_is_a_lower_bound_no_denser_sampling_beats(panda: ck.Robot) -> None:
    collision = ck.CollisionWorld(panda, []).self_collision
    assert collision is not None
    for k, (a, b) in enumerate(random_curves(panda, 12, 5)):
        bend = np.random.default_rng(k).normal(0.0, 0.3, panda.nq)

        def curve(t: np.ndarray, a: np.ndarray = a, b: np.ndarray = b, bend: np.ndarray = bend) -> np.ndarray:
            s = np.asarray(t)[:, None]
            return np.asarray(a + s * (b - a) + 4 * s * (1 - s) * bend)

        speed = np.abs(b - a) + 4 * np.abs(bend)  # bounds |q'(t)| on [0, 1]
        check = check_self_curve(collision, curve, (0.0, 1.0), speed, 0.0, 0.01)
        dense = np.linspace(0.0, 1.0, 20_000)
        assert collision.distances(curve(dense))[0].min() >= check.certified_min_m - 1e-9


def test_a_pairs_distance_changes_no_faster_than_its_relative_radii(panda: ck.Robot) -> None:
    # oracle: coal's distances of each pair at a configuration and a small random step from it;
    # only the joints carrying one geometry of a pair and not the other count
    collision = ck.CollisionWorld(panda, []).self_collision
    assert collision is not None
    rng = np.random.default_rng(3)
    whole = ck.motion_radii(panda)
    for q in rng.uniform(panda.limits.lower, panda.limits.upper, (40, panda.nq)):
        step = rng.normal(0.0, 0.02, panda.nq)
        for p, radii in enumerate(collision.pair_radii):
            change = abs(
                float(
                    collision.pair_distances(np.array([q + step]), p)[0]
                    - collision.pair_distances(q[None], p)[0]
                )
            )
            assert change <= radii @ np.abs(step) + 1e-9
            assert np.all(radii <= 2 * whole + 1e-12)
    names = collision.pairs
    link5_finger = names.index(("panda_link5", "panda_leftfinger_0"))
    assert np.all(collision.pair_radii[link5_finger][:5] == 0.0)  # joints 1-5 carry both


def test_a_joint_turning_one_geometry_counts_the_nearer_of_the_two_to_its_axis() -> None:
    # vamp's UR5: its shoulder turns the upper arm (0.64 m from the axis at its far end) about
    # the base, which lies within a few centimetres of that axis: turning the base the other
    # way moves it no more. Oracle: coal's hull distance of every pair, one joint stepped at a time.
    ur5 = ck.load_robot(vamp_resources("ur5") / "ur5.urdf", srdf=vamp_resources("ur5") / "ur5.srdf")
    collision = ck.CollisionWorld(ur5, []).self_collision
    reach = robot_reach(ur5)
    unturned = [dataclasses.replace(r, below=np.full_like(r.below, np.inf)) for r in reach]
    one_sided = relative_radii(ur5.model, ur5.collision_model, collision._pairs, unturned)
    radii = collision.pair_radii
    assert np.all(radii <= one_sided) and radii.sum() < 0.7 * one_sided.sum()
    links = [(ur5.geometries[a].link, ur5.geometries[b].link) for a, b in collision._pairs]
    base_arm = links.index(("base_link", "upper_arm_link"))
    assert radii[base_arm, 0] < 0.25 * one_sided[base_arm, 0]
    model, geometry_model = ur5.model, collision.geometry_model
    data, geometry_data = model.createData(), geometry_model.createData()

    def hull_distances(q: np.ndarray) -> np.ndarray:
        pin.computeDistances(model, data, geometry_model, geometry_data, q)
        return np.array([r.min_distance for r in geometry_data.distanceResults])

    rng = np.random.default_rng(8)
    tightest = 0.0
    for q in rng.uniform(ur5.limits.lower, ur5.limits.upper, (40, ur5.nq)):
        before = hull_distances(q)
        for j in range(ur5.nq):
            step = np.zeros(ur5.nq)
            step[j] = rng.choice([-1.0, 1.0]) * rng.uniform(0.001, 0.05)
            change = np.abs(hull_distances(q + step) - before)
            assert np.all(change <= radii[:, j] * abs(step[j]) + 2e-6)  # coal: 1e-6
            tightest = max(tightest, float(change[base_arm] / (radii[base_arm, j] * abs(step[j]) or 1.0)))
    assert tightest > 0.2  # the base pair's bound is not loose by orders of magnitude


def test_relative_radii_default_to_the_reach_within_the_models_limits(panda: ck.Robot) -> None:
    model, collision_model = panda.model, panda.collision_model
    pairs = ck.CollisionWorld(panda, []).self_collision._pairs
    within = geometry_reach(model, collision_model, model.lowerPositionLimit, model.upperPositionLimit)
    by_default = relative_radii(model, collision_model, pairs)
    np.testing.assert_array_equal(by_default, relative_radii(model, collision_model, pairs, within))
    assert relative_radii(model, collision_model, []).shape == (0, model.njoints - 1)
    names = [f"{a}-{b}" for a, b in pairs]
    np.testing.assert_array_equal(SelfCollision(model, collision_model, pairs, names).pair_radii, by_default)


def test_the_certificate_computes_few_samples_and_equals_computing_every_one(panda: ck.Robot) -> None:
    # each pair is sampled at its own relative speed; the samples coal skips are bounded from
    # their neighbours and the capsules: the certified minimum, the worst sample and its pair are
    # those of the distances at every sample of every pair (a pair whose distance stays flat at
    # the minimum, a link turning about its own axis, needs them all)
    collision = ck.CollisionWorld(panda, []).self_collision
    assert collision is not None
    computed, sampled = 0, 0
    for a, b in random_curves(panda, 12, 7):

        def line(t: np.ndarray, a: np.ndarray = a, b: np.ndarray = b) -> np.ndarray:
            return np.asarray(a + np.asarray(t)[:, None] * (b - a))

        speed = np.abs(b - a)
        check = check_self_curve(collision, line, (0.0, 1.0), speed, 0.0, 0.001)
        certified, worst = np.inf, (np.inf, 0.0, -1)
        for p, radii in enumerate(collision.pair_radii):
            pair_speed = float(radii @ speed)
            times = np.linspace(0.0, 1.0, max(int(np.ceil(pair_speed / 0.002)) + 1, 2))
            every = collision.pair_distances(line(times), p)
            certified = min(
                certified, float(np.min(0.5 * (every[:-1] + every[1:] - pair_speed * np.diff(times))))
            )
            k = int(np.argmin(every))
            worst = min(worst, (float(every[k]), float(times[k]), p))
        assert check.certified_min_m == pytest.approx(certified, abs=1e-12)
        assert check.worst_time == pytest.approx(worst[1])
        assert check.worst_pair == collision.pairs[worst[2]]
        computed, sampled = computed + check.computed, sampled + check.checks
    assert computed < 0.2 * sampled  # most pairs and samples are bounded, not computed


def poses_whose_line(
    panda: ck.Robot, seed: int, draws: int, wanted: Callable[[np.ndarray], bool]
) -> tuple[np.ndarray, np.ndarray]:
    """Two random poses whose straight joint-space line's self distances (41 samples) are ``wanted``."""
    collision = ck.CollisionWorld(panda, []).self_collision
    rng = np.random.default_rng(seed)
    for _ in range(draws):
        a, b = rng.uniform(panda.limits.lower, panda.limits.upper, (2, panda.nq))
        if wanted(collision.distances(a + np.linspace(0, 1, 41)[:, None] * (b - a))[0]):
            return a, b
    raise AssertionError("no pair of poses found")


def folded_through_itself(panda: ck.Robot) -> tuple[np.ndarray, np.ndarray]:
    """Two poses clear of themselves whose straight joint-space line passes through the arm."""
    return poses_whose_line(panda, 11, 2000, lambda d: d[0] > 0.05 and d[-1] > 0.05 and d.min() < -0.01)


def test_a_plan_goes_around_its_own_arm_and_passes_the_check(panda: ck.Robot) -> None:
    a, b = folded_through_itself(panda)
    scene = Scene(start=Target(q=tuple(a)), goal=Target(q=tuple(b)), self_margin=0.01)
    result = plan(scene, panda)
    assert result.verification.accepted
    trajectory = result.trajectory
    dense = trajectory(np.linspace(0.0, trajectory.duration, 4000))
    assert result.problem.world.self_collision.distances(dense)[0].min() >= 0.01 - 1e-9


def test_a_start_inside_itself_is_refused_unless_allowed(panda: ck.Robot) -> None:
    collision = ck.CollisionWorld(panda, []).self_collision
    q = np.random.default_rng(2).uniform(panda.limits.lower, panda.limits.upper, (400, panda.nq))
    distance, pair = collision.distances(q)
    inside = int(np.argmin(distance))
    a, b = collision.pairs[int(pair[inside])]
    scene = Scene(start=Target(q=tuple(q[inside])), goal=Target(q=tuple(q[inside])))
    with pytest.raises(
        PlanningError, match=rf"start .* is inside the self margin: {a} is -?[0-9.]+ m from {b}"
    ):
        plan(scene, panda)
    links = {g.name: g.link for g in panda.geometries}
    allowed = tuple(
        (links[x], links[y]) for x, y in collision.pairs if collision_distance(panda, q[inside], x, y) < 0.01
    )
    assert plan(
        Scene(start=scene.start, goal=scene.goal, allowed_collisions=allowed), panda
    ).verification.accepted
    misspelt = ((allowed[0][0], "panda_lnk7"), *allowed[1:])  # the pair would stay checked, silently
    with pytest.raises(PlanningError, match=r"allowed_collisions names \['panda_lnk7'\], not links"):
        plan(Scene(start=scene.start, goal=scene.goal, allowed_collisions=misspelt), panda)


def collision_distance(robot: ck.Robot, q: np.ndarray, first: str, second: str) -> float:
    index = {g.name: g.index for g in robot.geometries}
    return float(distances(robot, q[None], ((index[first], index[second]),))[0])


@pytest.mark.parametrize("margin_m", [0.0, 0.01, 0.05])
def test_the_fast_violation_test_agrees_with_the_distances(panda: ck.Robot, margin_m: float) -> None:
    collision = ck.CollisionWorld(panda, []).self_collision
    q = np.random.default_rng(4).uniform(panda.limits.lower, panda.limits.upper, (600, panda.nq))
    distance, _ = collision.distances(q)
    violated = collision.violated(q, margin_m)
    assert 0 < violated.sum() < len(q)
    np.testing.assert_array_equal(violated, distance < margin_m)


def near_itself(panda: ck.Robot) -> tuple[np.ndarray, np.ndarray]:
    """Two poses whose straight joint-space line passes 1-3 cm from the arm itself, midway."""
    return poses_whose_line(
        panda, 5, 4000, lambda d: 0.01 < d.min() < 0.03 and min(d[0], d[-1]) > d.min() + 0.02
    )


def test_the_self_check_asks_its_own_finer_step_beyond_the_self_margin(panda: ck.Robot) -> None:
    a, b = near_itself(panda)
    scene = Scene(start=Target(q=tuple(a)), goal=Target(q=tuple(b)), self_margin=0.0)
    objective = build_problem(scene, panda).objective
    straight = objective.straight_line()[None]
    samples = objective.paths(objective.nodes(straight)).samples[0]
    closest = float(objective.world.self_collision.distances(samples)[0].min())
    # the self margin 3 mm below the line's closest sample: within the default self step's
    # 1 mm beyond it, not within the obstacle step's 5 mm
    scene = dataclasses.replace(scene, self_margin=closest - 0.003)
    problem = build_problem(scene, panda)
    assert problem.scene.planner.self_step_m == 0.001
    assert problem.objective.required_self_m == pytest.approx(closest - 0.002)
    assert problem.objective.breakdown(straight).feasible[0]
    coarse = with_planner(problem, self_verify_step_m=0.005)
    assert coarse.objective.required_self_m == pytest.approx(closest + 0.002)
    assert not coarse.objective.breakdown(straight).feasible[0]
    result = plan(scene, panda)  # certified at the finer step too
    assert result.verification.accepted
    dense = result.trajectory(np.linspace(0.0, result.trajectory.duration, 4000))
    assert result.problem.world.self_collision.distances(dense)[0].min() >= scene.self_margin - 1e-9


def test_the_self_step_is_never_coarser_than_the_obstacle_step() -> None:
    settings = PlannerSettings(verify_step_m=0.0005)
    assert settings.self_step_m == 0.0005 and PlannerSettings().self_step_m == 0.001
    refused = r"self_verify_step_m = 0.5 m must be a number in \[0.0001, 0.1\] m"
    with pytest.raises(PlanningError, match=refused):
        PlannerSettings(self_verify_step_m=0.5)


def test_an_end_inside_the_self_margin_of_a_robot_without_an_srdf_says_so() -> None:
    # Baxter's SRDF is not named after its URDF: without it, its elbow's two collision links
    # overlap in nearly every configuration, and the message points at the missing file
    urdf, srdf = BAXTER / "urdf" / "baxter.urdf", BAXTER / "srdf" / "baxter_manipulation.srdf"
    start = [-0.4969, -1.0176, 1.5676, 1.2144, 1.5085, -0.6318, -0.879]
    scene = Scene(start=Target(q=tuple(start)), goal=Target(q=tuple(start)))
    bare = ck.load_robot(urdf, tcp="left_gripper")
    with pytest.raises(PlanningError, match=r"inside the self margin: .*no SRDF was found for this URDF"):
        build_problem(scene, bare)
    listed = ck.load_robot(urdf, tcp="left_gripper", srdf=srdf)
    assert build_problem(scene, listed).robot.srdf_path == srdf


def test_a_stoppable_self_check_decides_as_one_that_is_not_until_stopped(panda: ck.Robot) -> None:
    collision = ck.CollisionWorld(panda, []).self_collision
    assert collision is not None
    for a, b in random_curves(panda, 3, 11):

        def line(t: np.ndarray, a: np.ndarray = a, b: np.ndarray = b) -> np.ndarray:
            return np.asarray(a + np.asarray(t)[:, None] * (b - a))

        args = (collision, line, (0.0, 1.0), np.abs(b - a), 0.0, 0.0005)
        asked, never = after_calls(10**9)
        assert check_self_curve(*args, stop=never) == check_self_curve(*args)
        assert len(asked) > 1  # asked before the screen and each pair and piece it computes
        asked, at_once = after_calls(len(asked) - 1)  # stopped at its last question
        with pytest.raises(ck.CheckStoppedError):
            check_self_curve(*args, stop=at_once)


def test_robot_info_names_the_links_an_srdf_names_and_the_urdf_lacks(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from planning.cli import main

    srdf = tmp_path / "other.srdf"
    srdf.write_text('<robot><disable_collisions link1="arm_link" link2="elbow"/></robot>')
    urdf = str(ck.cpr_urdf_path())
    assert main(["robot-info", urdf, "--tcp", "tcp", "--srdf", str(srdf)]) == 0
    said = capsys.readouterr().out
    assert f"SRDF: {srdf} (it names links the URDF lacks: elbow; their disable_collisions entries" in said
    assert main(["robot-info", urdf, "--tcp", "tcp", "--srdf", str(srdf), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["srdf_unknown_links"] == ["elbow"]
