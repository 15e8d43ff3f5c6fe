"""Scenes drawn for any arm: start and goal keep their clearances, far apart, the ball on the arm's side."""

from __future__ import annotations

import csv
import dataclasses
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import cpr_kin as ck
from cpr_kin.model.packages import example_robot, example_robot_data_share
from planning.bench.arm_scenes import blocked_scene, reaching_side
from planning.bench.mbm import endpoint_violations
from planning.errors import PlanningError
from planning.io.scene_file import parse_scene
from planning.pipeline.endpoints import margin_violation
from planning.pipeline.planner import plan
from planning.pipeline.problem import build_problem
from planning.pipeline.verification import verify_for_scene


@pytest.fixture(scope="module")
def ur5() -> ck.Robot:
    return ck.load_robot(example_robot("ur5"))


@pytest.mark.parametrize("seed", [0, 1])
def test_start_and_goal_keep_their_clearances_and_lie_apart(ur5: ck.Robot, seed: int) -> None:
    document = blocked_scene(f"ur5_{seed}", "ur5", ur5, seed, margin_m=0.03, self_clearance_m=0.02)
    problem = build_problem(parse_scene(document), ur5)  # the goal pose solved by the IK, verified
    world, ends = problem.world, np.array([problem.q_start, problem.q_goal])
    assert world.clearance_batch(ends).clearance_m.min() > 0.03
    assert world.self_collision is not None and world.self_collision.distances(ends)[0].min() > 0.02
    tools = ck.frame_poses(ur5, ends)[:, :3, 3]
    ball = np.array(document["obstacles"][0]["xyz"])
    reach = document["obstacles"][0]["radius"] / 0.12
    assert np.linalg.norm(tools[0] - tools[1]) >= 0.5 * reach and ball[2] >= 0.1 * reach
    assert blocked_scene(f"ur5_{seed}", "ur5", ur5, seed, margin_m=0.03) == document  # seeded


def test_start_and_goal_are_ends_the_motors_can_hold_still() -> None:
    # Baxter's left shoulder (left_s1, 50 N m) cannot hold its arm stretched out: seed 19's
    # first draw that keeps the clearances needs 54 N m there, which the planner refuses
    share = example_robot_data_share()
    assert share is not None, "example-robot-data is part of the robots extra, which make installs"
    folder = share / "example-robot-data" / "robots" / "baxter_description"
    entry = {
        "urdf": str(folder / "urdf" / "baxter.urdf"),
        "tcp": "left_gripper",
        "srdf": str(folder / "srdf" / "baxter_manipulation.srdf"),
    }
    baxter = ck.load_robot(entry["urdf"], tcp=entry["tcp"], srdf=entry["srdf"])
    dynamics = ck.robot_dynamics(baxter)
    for seed in (19, 21):
        document = blocked_scene(f"baxter_{seed}", entry, baxter, seed, self_clearance_m=0.015)
        problem = build_problem(parse_scene(document), baxter)  # refuses an end it cannot hold
        holding = dynamics.torques(np.array([problem.q_start, problem.q_goal]))
        assert np.all(np.abs(holding) <= dynamics.effort)


def test_no_qualifying_draw_is_an_error_naming_the_fix(ur5: ck.Robot) -> None:
    assert ur5.srdf_path is not None
    with pytest.raises(
        PlanningError,
        match=r"no start and goal of 20 draws .* 1 m between .* \(refused: .*\d+ with the robot's own pairs "
        r"too close.*\); lower self_clearance_m \(\d+ of the \d+ draws "
        r"refused for their own pairs had \w+ and \w+ closest: if they sit that close by design, allow "
        r"the pair in the SRDF\)$",
    ):  # the pair most often closest among the draws the self clearance refused
        blocked_scene("ur5_0", "ur5", ur5, 0, self_clearance_m=1.0, draws=20)
    with pytest.raises(PlanningError, match=r"draws = 0 must be a whole number >= 1"):
        blocked_scene("ur5_0", "ur5", ur5, 0, draws=0)
    with pytest.raises(PlanningError, match=r"seed = -1 must be an integer in \[0, "):
        blocked_scene("ur5_0", "ur5", ur5, -1)
    ur10 = ck.load_robot(example_robot("ur10"))  # example-robot-data has no SRDF for it
    with pytest.raises(PlanningError, match=r"lower self_clearance_m, or give the robot its SRDF"):
        blocked_scene("ur10_0", "ur10", ur10, 0, self_clearance_m=1.0, draws=20)


def test_a_self_clearance_below_the_self_margin_lowers_the_scenes_margin() -> None:
    """UR3 (no SRDF) at 5 mm: its ends lie outside the default 10 mm self margin only with it lowered.

    Before, scenes 901 and 904 put the start inside the default margin, and the benchmarks
    counted them invalid.
    """
    ur3 = ck.load_robot(example_robot("ur3"))
    for seed in (901, 904):
        document = blocked_scene(f"ur3_{seed}", "ur3", ur3, seed, self_clearance_m=0.005)
        assert document["self_margin"] == 0.0025
        assert endpoint_violations(parse_scene(document), ur3) == []
    assert "self_margin" not in blocked_scene(
        "ur3_900", "ur3", ur3, 900, self_clearance_m=0.01
    )  # the default


def test_a_bad_margin_is_named_before_any_draw(ur5: ck.Robot) -> None:
    with pytest.raises(PlanningError, match=r"margin_m = -0\.01 m must be a number in \[0, 1\] m"):
        blocked_scene("ur5_0", "ur5", ur5, 0, margin_m=-0.01)
    with pytest.raises(PlanningError, match=r"self_clearance_m = 0\.0 m must be a number in \(0, 1\] m"):
        blocked_scene("ur5_0", "ur5", ur5, 0, self_clearance_m=0.0)


def test_the_script_writes_no_file_when_a_scene_cannot_be_drawn(tmp_path: Path) -> None:
    script = Path(__file__).resolve().parent.parent / "scripts" / "generate_arm_scenes.py"
    out = tmp_path / "none"
    done = subprocess.run(
        [sys.executable, str(script), "--robot=ur5", "--count=2", "--self-clearance=1", f"--out={out}"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 2 and done.stderr.startswith("generate_arm_scenes: no start and goal")
    assert "Traceback" not in done.stderr and not out.exists()


def test_an_arm_that_hangs_below_its_base_gets_its_ball_below_it_and_plans() -> None:
    # example-robot-data's hextilt flying arm hangs below the drone: every draw's midway tool
    # point lay below the base, and the generator refused it ("write its scenes by hand")
    share = example_robot_data_share()
    assert share is not None
    urdf = share / "example-robot-data/robots/hextilt_description/urdf/hextilt_flying_arm_5.urdf"
    arm = ck.load_robot(urdf)
    reach = float(
        np.linalg.norm(ck.frame_poses(arm, ((arm.limits.lower + arm.limits.upper) / 2)[None])[0][:3, 3])
    )
    assert reaching_side(arm, reach) == -1
    document = blocked_scene("hextilt_0", str(urdf), arm, 0)
    ball = document["obstacles"][0]
    assert ball["xyz"][2] <= -0.1 * ball["radius"] / 0.12  # a tenth of the reach below the base
    scene = parse_scene(document)
    result = plan(scene, arm)
    assert not verify_for_scene(build_problem(scene, arm), result.trajectory).problems  # `check`'s verdict
    for name in ("ur5", "panda"):  # arms that reach up (the UR about as far below its base as above)
        robot = ck.load_robot(example_robot(name))
        assert reaching_side(robot, 1.0) == 1


PLANAR_ARM = """<robot name="planar">
  <link name="base"/>
  <link name="upper"><collision><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.04 0.04"/></geometry>
    </collision></link>
  <link name="fore"><collision><origin xyz="0.15 0 0"/><geometry><box size="0.3 0.04 0.04"/></geometry>
    </collision></link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="upper"/><axis xyz="0 0 1"/>
    <limit lower="-2.5" upper="2.5" velocity="1" effort="100"/></joint>
  <joint name="j2" type="revolute"><parent link="upper"/><child link="fore"/><origin xyz="0.3 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-2.5" upper="2.5" velocity="1" effort="100"/></joint>
  <joint name="t" type="fixed"><parent link="fore"/><child link="tool"/><origin xyz="0.3 0 0"/></joint>
</robot>
"""


def test_an_arm_that_moves_in_its_bases_horizontal_plane_is_told_why_it_gets_no_scene(tmp_path: Path) -> None:
    urdf = tmp_path / "planar.urdf"
    urdf.write_text(PLANAR_ARM)
    arm = ck.load_robot(urdf)
    with pytest.raises(
        PlanningError,
        match=r"\(refused: .*\d+ with the tool's midway point less than a tenth of the reach from the "
        r"base's height.*\); the generator puts the ball a tenth of the reach above the base .* an arm "
        r"that moves about its base's height \(in its horizontal plane\) has no such scene",
    ):
        blocked_scene("planar_0", str(urdf), arm, 0, draws=50)


def test_a_goal_pose_is_valid_when_a_clear_ik_solution_reaches_it() -> None:
    """The benchmarks' validity test finds the ends as the planner does, not by the IK's first solution.

    UR10 scene 461 (self clearance 15 mm at its drawn goal), on the links' hulls alone: the
    IK solution nearest mid-range, taken without the margins, puts the forearm's hull inside
    the self margin of the wrist's; another solution of the same pose keeps every margin, and
    the planner takes it. (On the exact meshes that decide, the first solution is clear too.)
    """
    ur10 = dataclasses.replace(ck.load_robot(example_robot("ur10")), exact_meshes={})
    scene = parse_scene(blocked_scene("ur10_461", "ur10", ur10, 461, self_clearance_m=0.015))
    world = ck.CollisionWorld(ur10, scene.obstacles)
    first = margin_violation(world, scene, scene.goal.configuration(ur10))
    assert first is not None and "self margin" in first  # the IK alone lands inside it
    assert endpoint_violations(scene, ur10) == []
    problem = build_problem(scene, ur10)
    assert margin_violation(problem.world, scene, problem.q_goal) is None
    assert scene.goal.miss(ur10, problem.q_goal) is None  # and it reaches the pose


def test_an_end_inside_a_margin_is_named(ur5: ck.Robot) -> None:
    document = blocked_scene("ur5_0", "ur5", ur5, 0)
    document["obstacles"][0]["radius"] = 5.0  # the ball swallows the robot
    (violation,) = [v for v in endpoint_violations(parse_scene(document), ur5) if v.startswith("start")]
    assert "inside the safety margin" in violation and "ball" in violation


def test_the_ends_are_checked_with_the_payloads_shape_as_the_planner_checks_them(ur5: ck.Robot) -> None:
    """A carried sphere held inside the ball at the start: the validity test finds it as the planner does."""
    document = blocked_scene("ur5_0", "ur5", ur5, 0)
    scene = parse_scene(document)
    assert endpoint_violations(scene, ur5) == []
    tool_in_base = ck.frame_poses(ur5, build_problem(scene, ur5).q_start[None])[0]
    ball_in_base = np.asarray(scene.obstacles[0].xyz)
    ball_in_tool = tool_in_base[:3, :3].T @ (ball_in_base - tool_in_base[:3, 3])
    document["payload"] = {
        "mass_kg": 0.0,
        "shape": {"shape": "sphere", "radius": 0.01, "xyz": ball_in_tool.tolist()},
    }
    carried = parse_scene(document)
    (violation,) = [v for v in endpoint_violations(carried, ur5) if v.startswith("start")]
    assert "ball" in violation
    with pytest.raises(PlanningError, match="ball"):
        build_problem(carried, ur5)


@pytest.mark.slow
def test_the_scripts_draw_scenes_and_run_them_beside_ompl(tmp_path: Path) -> None:
    """The README's two commands for one's own arm: scene files, then both planners on them."""
    pytest.importorskip("ompl")
    root = Path(__file__).resolve().parent.parent
    scenes, scripts = tmp_path / "xarm7", root / "scripts"
    draw = ["--robot", "xarm7", "--count", "1", "--seed", "5", "--out", str(scenes)]
    drawn = subprocess.run(
        [sys.executable, str(scripts / "generate_arm_scenes.py"), *draw],
        capture_output=True,
        text=True,
        check=False,
    )
    assert drawn.returncode == 0, drawn.stderr[-2000:]
    assert sorted(p.name for p in scenes.iterdir()) == ["xarm7_5.yaml"]
    files = [str(p) for p in sorted(scenes.iterdir())]
    bench = subprocess.run(
        [
            sys.executable,
            str(scripts / "bench_mbm.py"),
            "--scenes",
            *files,
            "--workers",
            "2",
            "--out",
            str(tmp_path / "bench"),
        ],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert bench.returncode == 0, bench.stderr[-2000:]
    with (tmp_path / "bench" / "mbm.csv").open() as rows:
        read = list(csv.DictReader(rows))
    assert [(r["robot"], r["class"], r["problem"]) for r in read] == [("xarm7", "xarm7", "5")]
    assert all(r["ours_ok"] == "True" and float(r["ours_time_s"]) > 0 for r in read)
    assert all(r["ours_checked"] == "True" for r in read)  # cpr-plan check's verdict on the file
    table = (tmp_path / "bench" / "mbm.md").read_text()
    assert "| xarm7 | all | 1 | 1 |" in table and "| OMPL beyond an effort limit |" in table
    assert all(float(r["ompl_torque"]) > 0 for r in read if r["ompl_ok"] == "True")  # gravity at least


@pytest.mark.slow
def test_the_script_writes_the_srdf_it_is_given_into_the_scenes(tmp_path: Path) -> None:
    # Baxter's SRDF is not named after its URDF: without it, none of its left arm's random
    # configurations keeps 20 mm between its own pairs
    share = example_robot_data_share()
    assert share is not None
    folder = share / "example-robot-data" / "robots" / "baxter_description"
    urdf, srdf = folder / "urdf" / "baxter.urdf", folder / "srdf" / "baxter_manipulation.srdf"
    script = Path(__file__).resolve().parent.parent / "scripts" / "generate_arm_scenes.py"
    command = [sys.executable, str(script), "--robot", str(urdf), "--tcp", "left_gripper", "--count", "1"]
    done = subprocess.run(
        [*command, "--srdf", str(srdf), "--out", str(tmp_path / "b")], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr[-2000:]
    scene = parse_scene(yaml.safe_load((tmp_path / "b" / "baxter_0.yaml").read_text()))
    assert scene.robot is not None and scene.robot.srdf == srdf
    build_problem(scene, scene.robot.load())  # start and goal keep their margins with its pairs


def test_the_ends_pass_the_planners_check_where_a_pair_close_by_design_is_held_to_its_margin() -> None:
    # Bolt's leg: base_link and FL_UPPER_LEG sit at most 19 mm apart. A world of the 0.02 m self
    # clearance let them touch; the scene's 0.01 m self margin holds them to it, and the planner
    # refused the drawn ends ("goal q = [...] is inside the self margin: base_link is 0.002 m
    # from FL_UPPER_LEG")
    share = example_robot_data_share()
    assert share is not None
    urdf = share / "example-robot-data/robots/bolt_description/robots/bolt.urdf"
    leg = ck.load_robot(urdf, tcp="FL_FOOT")
    assert leg.close_pairs and leg.close_pairs[0].largest_m > 0.01  # the case: above the scene's margin
    for seed in (1207, 1208):
        scene = parse_scene(blocked_scene(f"bolt_{seed}", {"urdf": str(urdf), "tcp": "FL_FOOT"}, leg, seed))
        problem = build_problem(scene, leg)  # the planner's own check of the ends: it raised
        for q in (problem.motion.q_start, problem.motion.q_goal):
            assert margin_violation(problem.world, scene, q) is None


def test_a_robot_whose_meshes_name_a_package_elsewhere_is_given_its_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a maker's URDF names its meshes 'package://NAME/...' of a package no search path holds:
    # robot-info and the scene generator take the folder as a scene's robot: {packages} does
    from planning.cli import main

    share = example_robot_data_share()
    assert share is not None
    text = example_robot("ur5").read_text().replace("package://example-robot-data/", "package://my_arm_pkg/")
    urdf = tmp_path / "my_ur5.urdf"
    urdf.write_text(text)
    (tmp_path / "packages").mkdir()
    (tmp_path / "packages" / "my_arm_pkg").symlink_to(share / "example-robot-data", target_is_directory=True)
    assert main(["robot-info", str(urdf), "--json"]) == 2
    assert "my_arm_pkg" in capsys.readouterr().err
    assert main(["robot-info", str(urdf), "--package-dir", str(tmp_path / "packages"), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    robot = ck.load_robot(example_robot("ur5"))  # the oracle: the same arm, its meshes found by name
    assert [j["name"] for j in report["joints"]] == list(robot.joint_names)
    assert [s["geometry"] for s in report["shapes"]] == [g.name for g in robot.geometries]
    script = Path(__file__).resolve().parent.parent / "scripts" / "generate_arm_scenes.py"
    command = [sys.executable, str(script), "--robot", str(urdf), "--count", "1", "--seed", "3"]
    packages = ["--package-dir", str(tmp_path / "packages"), "--out", str(tmp_path / "scenes")]
    done = subprocess.run([*command, *packages], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    scene = parse_scene(yaml.safe_load((tmp_path / "scenes" / "my_ur5_3.yaml").read_text()))
    assert scene.robot is not None and scene.robot.package_dirs == ((tmp_path / "packages").resolve(),)
    build_problem(scene, scene.robot.load())


def test_the_script_names_the_bundled_robot_as_a_scene_does(tmp_path: Path) -> None:
    # '--robot cpr' was read as a file's path: "URDF file '.../cpr' does not exist"
    script = Path(__file__).resolve().parent.parent / "scripts" / "generate_arm_scenes.py"
    command = [sys.executable, str(script), "--robot", "cpr", "--count", "1", "--out", str(tmp_path)]
    done = subprocess.run(command, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-2000:]
    document = yaml.safe_load((tmp_path / "cpr_0.yaml").read_text())
    assert document["robot"] == "cpr"
    scene = parse_scene(document)
    assert scene.robot == ck.cpr_spec()
    build_problem(scene, scene.robot.load())  # its ends keep their margins
