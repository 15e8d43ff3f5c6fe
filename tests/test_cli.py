from __future__ import annotations

import json
import os
import pty
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import cpr_kin as ck
from cpr_kin.common.compiled import COMPILING
from planning.cli import main
from planning.io.trajectory_reader import read_trajectory
from planning.pipeline.metrics import WALL_TIMES

from .conftest import strict_loads

SCENE: dict[str, Any] = {
    "name": "swing",
    "safety_margin": 0.1,
    "start": {"tcp": [0.5, 0.45, 0.25]},
    "goal": {"tcp": [-0.5, 0.45, 0.25]},
    "duration": 4.0,
    "obstacles": [{"name": "crate", "shape": "box", "size": [0.3, 0.3, 0.3], "xyz": [0.0, 0.6, 0.15]}],
    "planner": {"seed": 1},
    "spline": {"ends": "natural"},
}


def write_scene(folder: Path, document: Any, name: str = "scene.yaml") -> Path:
    path = folder / name
    path.write_text(document if isinstance(document, str) else yaml.safe_dump(document))
    return path


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def with_changes(**changes: Any) -> dict[str, Any]:
    document: dict[str, Any] = json.loads(json.dumps(SCENE))
    for dotted, value in changes.items():
        target = document
        *parents, last = dotted.split("__")
        for key in parents:
            target = target[int(key)] if isinstance(target, list) else target[key]
        target[last] = value
    return document


PANDA: dict[str, Any] = {
    "robot": "panda",
    "safety_margin": 0.02,
    "start": {"q": [0.0, -0.6, 0.0, -2.2, 0.0, 1.6, 0.8]},
    "goal": {"pose": {"xyz": [0.45, 0.35, 0.25], "rpy": [3.14159, 0.0, 0.0]}},
}

BAD_INPUTS = [
    ("broken YAML", "start: {tcp: [0.5, 0.45\n", "is not valid YAML"),
    ("not a mapping", "- start\n- goal\n", "must be a mapping of keys"),
    ("misspelt key", with_changes(safty_margin=0.1), "safty_margin: unknown key"),
    ("negative size", with_changes(obstacles__0__size=[0.3, -0.3, 0.3]), "obstacles[0].size[1] = -0.3"),
    ("negative margin", with_changes(safety_margin=-0.1), "safety_margin = -0.1"),
    ("NaN", with_changes(obstacles__0__xyz=[0.0, float("nan"), 0.15]), "obstacles[0].xyz[1] = nan"),
    ("unknown shape", with_changes(obstacles__0__shape="pyramid"), "obstacles[0].shape = 'pyramid'"),
    (
        "short joint vector",
        with_changes(start={"q": [0.7, 0.15, 0.37]}),
        "start.q: joint vector [0.7, 0.15, 0.37] has 3 value(s); expected 5",
    ),
    (
        "joint outside limits",
        with_changes(start={"q": [0.7, 0.9, 0.37, 0, 0]}),
        "joint 'd2' = 0.9 m is outside [0, 0.6] m",
    ),
    (
        "unknown moving joint",
        with_changes(planner__moving_joints=["elbow"]),
        "planner.moving_joints names ['elbow'], not among the robot's planned joints",
    ),
    ("goal inside margin", with_changes(goal={"tcp": [0.0, 0.45, 0.38]}), "goal q = "),  # 0.08 m, margin 0.1
    (
        "panda: six values",
        {**PANDA, "start": {"q": [0.0] * 6}},
        "start.q: joint vector [0.0, 0.0, 0.0, 0.0, 0.0, 0.0] has 6 value(s); expected 7",
    ),
    (
        "panda: unknown joint name",
        {**PANDA, "start": {"q": {"panda_joint1": 0.0, "elbow": 1.0}}},
        "unknown joint 'elbow'",
    ),
    (
        "panda: value out of range",
        {**PANDA, "start": {"q": [0.0, -0.6, 0.0, 0.5, 0.0, 1.6, 0.8]}},
        "joint 'panda_joint4' = 0.5 rad is outside [-3.0718, -0.0698] rad",
    ),
    (
        "panda: a held joint it does not plan",
        {**PANDA, "goal": {"tcp": [0.4, 0.0, 0.4], "hold": {"theta4": 1.0}}},
        "['theta4'] not planned joint(s) of this robot",
    ),
    (
        "unknown robot",
        {**PANDA, "robot": "no_such_robot"},
        "robot: 'no_such_robot' is neither a URDF file",
    ),
    (
        "a robot's name in capitals",
        {**PANDA, "robot": "UR5"},
        "]; did you mean 'ur5'?",
    ),
    ("zero fireflies", with_changes(planner__fireflies=0), "planner.fireflies = 0"),
    ("negative time limit", with_changes(planner__time_limit_s=-1), "planner.time_limit_s = -1"),
    (
        "all spline weights zero",
        with_changes(spline__a=[0, 0, 0]),
        "a = [0, 0, 0] leaves the spline undetermined",
    ),
]


@pytest.mark.parametrize(("label", "document", "message"), BAD_INPUTS, ids=[b[0] for b in BAD_INPUTS])
def test_bad_input_exits_2_naming_the_value(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], label: str, document: Any, message: str
) -> None:
    scene = write_scene(tmp_path, document)
    out = tmp_path / "out"
    code, stdout, stderr = run(["plan", str(scene), "--out", str(out)], capsys)
    assert code == 2, label
    assert message in stderr
    assert "Traceback" not in stderr and stdout == ""
    assert len(stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_missing_scene_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, stderr = run(["plan", str(tmp_path / "nope.yaml"), "--out", str(tmp_path / "out")], capsys)
    assert code == 2 and "nope.yaml' does not exist" in stderr
    assert not (tmp_path / "out").exists()


def test_an_error_about_a_long_path_says_what_is_wrong(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the line is capped (a hostile input must not flood the terminal), but not before a path
    # of several hundred characters has left room for what is wrong
    deep = tmp_path.joinpath(*["folder_" * 20] * 4)  # 560 characters below tmp_path
    deep.mkdir(parents=True)
    missing = deep / "nope.yaml"
    code, _, stderr = run(["plan", str(missing), "--out", str(tmp_path / "out")], capsys)
    line = stderr.strip()
    assert code == 2 and len(line.splitlines()) == 1 and len(line) <= 1000
    assert line.startswith("cpr-plan plan: error: ") and line.endswith(f"'{missing}' does not exist")


def test_infeasible_scene_exits_3_writing_nothing(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    wall = {"name": "wall", "shape": "box", "size": [0.05, 1.3, 2.0], "xyz": [0.0, 0.95, 1.0]}
    scene = write_scene(tmp_path, with_changes(obstacles=[wall], planner={"fireflies": 10, "iterations": 5}))
    out = tmp_path / "out"
    code, _, stderr = run(["plan", str(scene), "--out", str(out)], capsys)
    assert code == 3
    assert "no collision-free trajectory found" in stderr and "wall" in stderr
    assert not out.exists()


def test_a_pose_out_of_reach_exits_3_with_the_distance(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(
        tmp_path, {**PANDA, "goal": {"pose": {"xyz": [1.5, 0.0, 0.4], "rpy": [3.14159, 0, 0]}}}
    )
    code, stdout, stderr = run(["plan", str(scene), "--out", str(tmp_path / "out")], capsys)
    assert code == 3 and stdout == "" and len(stderr.strip().splitlines()) == 1
    assert "goal is out of reach: no configuration puts frame 'panda_hand_tcp' at [1.5, 0.0, 0.4] m" in stderr
    assert not (tmp_path / "out").exists()


def test_an_unreachable_tcp_exits_3_with_the_distance(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path, with_changes(goal={"tcp": [1.2, 0.0, 0.3]}))
    out = tmp_path / "out"
    code, stdout, stderr = run(["plan", str(scene), "--out", str(out)], capsys)
    assert code == 3 and stdout == "" and len(stderr.strip().splitlines()) == 1
    assert "goal is out of reach: no configuration puts frame 'tcp' at [1.2, 0.0, 0.3] m" in stderr
    assert "m from the position (tolerance 0.0001 m)" in stderr
    assert "the robot's analytic IK: TCP target [1.2, 0.0, 0.3] is out of reach: joint 'd3' = 0.9 m" in stderr
    assert not out.exists()


def test_a_scene_without_obstacles_writes_json_any_parser_reads(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """No obstacle: the certified clearance is unbounded, ``null`` in JSON (which has no infinity)."""
    scene = write_scene(tmp_path, {**SCENE, "obstacles": []})
    out = tmp_path / "out"
    code, stdout, _ = run(["plan", str(scene), "--out", str(out), "--json"], capsys)
    assert code == 0
    summary = strict_loads(stdout)
    metrics = strict_loads((out / "trajectory.json").read_text())["metrics"]
    assert summary["min_clearance"] is None and metrics["min_clearance"] is None
    code, stdout, _ = run(["check", str(scene), str(out / "trajectory.json"), "--json"], capsys)
    assert code == 0
    checked = strict_loads(stdout)
    assert checked["status"] == "ok" and checked["certified_min_clearance_m"] is None
    assert checked["certified_step_m"] == metrics["certified_step"]  # the step that certified it
    # and what a person reads says why, not "inf m"
    code, stdout, _ = run(["plan", str(scene), "--out", str(tmp_path / "words")], capsys)
    assert code == 0 and "certified clearance unbounded, no obstacle (margin" in stdout
    report = (tmp_path / "words" / "report.md").read_text()
    assert "| certified min clearance | unbounded, no obstacle (margin" in report
    code, stdout, _ = run(["check", str(scene), str(out / "trajectory.json")], capsys)
    assert code == 0 and "certified clearance unbounded, no obstacle >= " in stdout
    assert "inf" not in stdout + report
    # the two files in the wrong order: one line saying which is which, not the scene's missing keys
    code, _, err = run(["check", str(out / "trajectory.json"), str(scene)], capsys)
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err
    assert "trajectory.json is a trajectory file (cpr-trajectory/1), not a scene; give the scene file" in err


def test_plan_check_and_reproducibility(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = write_scene(tmp_path, SCENE)
    first, second = tmp_path / "a", tmp_path / "b"
    code, stdout, _ = run(["plan", str(scene), "--out", str(first)], capsys)
    assert code == 0 and "verified trajectory" in stdout
    assert sorted(p.name for p in first.iterdir()) == [
        "manifest.json",
        "report.md",
        "samples.csv",
        "trajectory.json",
    ]
    code, stdout, _ = run(["plan", str(scene), "--out", str(second), "--json"], capsys)
    assert code == 0
    summary = json.loads(stdout)
    assert summary["status"] == "ok" and summary["min_clearance"] >= 0.1
    assert (first / "trajectory.json").read_bytes() == (second / "trajectory.json").read_bytes()
    # one serialisation: the summary carries the file's metrics, under the same keys
    recorded = json.loads((second / "trajectory.json").read_text())["metrics"]
    wall_times = set(WALL_TIMES)
    assert {k: summary[k] for k in recorded if k not in wall_times} == {
        k: v for k, v in recorded.items() if k not in wall_times
    }
    # another seed gives another trajectory
    code, _, _ = run(["plan", str(scene), "--out", str(tmp_path / "c"), "--seed", "7"], capsys)
    assert code == 0
    assert (tmp_path / "c" / "trajectory.json").read_bytes() != (first / "trajectory.json").read_bytes()
    # the trajectory passes its own scene, and fails one with an obstacle in its way
    code, stdout, _ = run(["check", str(scene), str(first / "trajectory.json")], capsys)
    assert code == 0 and "verified against" in stdout
    assert recorded["certified_step"] == 0.005 and "(at most 5 mm of robot motion apart)" in stdout
    trajectory = read_trajectory(first / "trajectory.json").trajectory
    # a ball around the tool tip where it is farthest from the robot at start and goal: the
    # scene stays valid, but the trajectory runs into the ball
    robot = ck.load_cpr()
    q = trajectory(np.linspace(0.0, trajectory.duration, 41))
    ends = q[[0, -1]]
    balls = [ck.Obstacle.sphere(0.05, p) for p in ck.frame_positions(robot, q)]
    farthest = max(
        balls, key=lambda b: ck.CollisionWorld(robot, [b]).clearance_batch(ends).min_clearance_m.min()
    )
    blocker = {"name": "post", "shape": "sphere", "radius": 0.05, "xyz": farthest.xyz.tolist()}
    other = write_scene(tmp_path, with_changes(obstacles=[*SCENE["obstacles"], blocker]), "other.yaml")
    code, stdout, err = run(["check", str(other), str(first / "trajectory.json"), "--json"], capsys)
    assert code == 3, err
    verdict = json.loads(stdout)
    assert verdict["status"] == "failed" and any("post" in p for p in verdict["problems"])


def test_timings_flag(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    scene = write_scene(tmp_path, SCENE)
    run(["plan", str(scene), "--out", str(tmp_path / "t"), "--timings"], capsys)
    metrics = json.loads((tmp_path / "t" / "trajectory.json").read_text())["metrics"]
    assert metrics["planning_time_s"] > 0
    run(["plan", str(scene), "--out", str(tmp_path / "u")], capsys)
    assert json.loads((tmp_path / "u" / "trajectory.json").read_text())["metrics"]["planning_time_s"] is None


def test_paper_command(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, stdout, _ = run(["paper", "--out", str(tmp_path / "paper")], capsys)
    assert code == 0
    assert "FMA processing time" in stdout and "53 s" in stdout
    assert "Beside the paper" in (tmp_path / "paper" / "report.md").read_text()
    # the paper's jerk ranges, one row per joint it names, in that joint's unit (the robot's)
    assert "jerk theta1 min / max                      -0.071 / 0.2026 rad/s^3" in stdout
    assert "-0.518 / 0.673 m/s^3" in stdout and "-0.292 / 0.265 m/s^3" in stdout


@pytest.mark.slow
@pytest.mark.parametrize("command", [[], ["plan"], ["paper"], ["check"]])
def test_help_everywhere(command: list[str]) -> None:
    completed = subprocess.run(
        [sys.executable, "-m", "planning.cli", *command, "--help"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert completed.returncode == 0
    assert "usage: cpr-plan" in completed.stdout


@pytest.mark.slow
def test_installed_console_script() -> None:
    script = Path(sys.executable).parent / "cpr-plan"
    assert script.exists(), "the project installs the cpr-plan command"
    completed = subprocess.run([str(script), "check", "--help"], capture_output=True, text=True, check=False)
    assert completed.returncode == 0 and "TRAJECTORY" in completed.stdout


@pytest.mark.slow
def test_usage_error_exits_2_without_traceback() -> None:
    completed = subprocess.run(
        [sys.executable, "-m", "planning.cli", "plan"], capture_output=True, text=True, check=False
    )
    assert completed.returncode == 2
    assert "the following arguments are required" in completed.stderr and "Traceback" not in completed.stderr


def on_a_terminal(command: list[str], env: dict[str, str] | None = None) -> tuple[int, bytes]:
    """Run ``command`` with stdout and stderr on a pseudo-terminal: its exit code and what it showed."""
    leader, follower = pty.openpty()
    process = subprocess.Popen(command, stdout=follower, stderr=follower, close_fds=True, env=env)
    os.close(follower)
    output = b""
    while True:
        try:
            chunk = os.read(leader, 4096)
        except OSError:  # the terminal closes when the process exits
            break
        if not chunk:
            break
        output += chunk
    code = process.wait(timeout=120)
    os.close(leader)
    return code, output


@pytest.mark.slow
def test_progress_bar_only_on_a_terminal(tmp_path: Path) -> None:
    scene = write_scene(tmp_path, SCENE)
    command = [sys.executable, "-m", "planning.cli", "plan", str(scene), "--out"]
    piped = subprocess.run([*command, str(tmp_path / "piped")], capture_output=True, text=True, check=False)
    assert piped.returncode == 0 and "it/s" not in piped.stdout + piped.stderr
    code, output = on_a_terminal([*command, str(tmp_path / "tty")])
    assert code == 0
    assert b"search" in output and b"best=" in output  # the bar, its seeds' best at least
    assert b"it/s" in output or b"s/it" in output


@pytest.mark.slow
def test_a_first_runs_compilation_is_said_on_a_terminal_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path, SCENE)
    assert run(["plan", str(scene), "--out", str(tmp_path / "out")], capsys)[0] == 0
    check = [
        sys.executable,
        "-m",
        "planning.cli",
        "check",
        str(scene),
        str(tmp_path / "out" / "trajectory.json"),
    ]
    notice = f"cpr-plan check: {COMPILING}".encode()

    def cold(name: str) -> dict[str, str]:  # a disk cache of kernels of its own: empty at first
        return {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / name)}

    piped = subprocess.run(check, capture_output=True, text=True, env=cold("piped"), check=False)
    assert piped.returncode == 0 and "verified against" in piped.stdout and piped.stderr == ""
    assert any((tmp_path / "piped").rglob("*.nbi"))  # it did compile: nothing said in a pipe
    code, shown = on_a_terminal(check, cold("terminal"))
    assert code == 0 and b"verified against" in shown and shown.count(notice) == 1, shown
    code, shown = on_a_terminal(check, cold("terminal"))  # loaded from the cache: nothing to say
    assert code == 0 and b"verified against" in shown and notice not in shown, shown


def test_paper_search_flag_is_the_papers_settings_written_in_the_scene(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path, SCENE)
    code, stdout, _ = run(
        ["plan", str(scene), "--out", str(tmp_path / "f"), "--paper-search", "--json"], capsys
    )
    assert code == 0
    assert json.loads(stdout)["evaluations"] == 50 * 51  # every iteration of the paper's 50 fireflies
    paper_planner = {
        **SCENE["planner"],
        "fireflies": 50,
        "iterations": 50,
        "alpha": 1.0,
        "beta0": 0.5,
        "gamma": 1.0,
        "theta": 0.97,
        "stall_iterations": 0,
        "seeding": "none",
        "refine": "none",
    }
    written = write_scene(tmp_path, with_changes(planner=paper_planner), "paper_search.yaml")
    code, _, _ = run(["plan", str(written), "--out", str(tmp_path / "w")], capsys)
    assert code == 0
    assert (tmp_path / "f" / "trajectory.json").read_bytes() == (
        tmp_path / "w" / "trajectory.json"
    ).read_bytes()
    # without the flag, the defaults search less
    code, stdout, _ = run(["plan", str(scene), "--out", str(tmp_path / "d"), "--json"], capsys)
    assert code == 0 and json.loads(stdout)["evaluations"] < 50 * 51


def test_show_refuses_a_trajectory_whose_robot_is_not_here(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path, SCENE)
    assert run(["plan", str(scene), "--out", str(tmp_path / "out")], capsys)[0] == 0
    document = json.loads((tmp_path / "out" / "trajectory.json").read_text())
    document["robot"] = "/elsewhere/robots/cpr.urdf"  # planned on another machine
    moved = tmp_path / "moved.json"
    moved.write_text(json.dumps(document))
    code, _, stderr = run(["show", str(moved), "--html", str(tmp_path / "v.html")], capsys)
    assert code == 2 and not (tmp_path / "v.html").exists()
    assert (
        "robot URDF '/elsewhere/robots/cpr.urdf' is not on this machine; pass the robot with --urdf" in stderr
    )
    # given another robot, it says whose joints differ and draws nothing
    code, _, stderr = run(["show", str(moved), "--html", str(tmp_path / "v.html"), "--urdf", "panda"], capsys)
    assert code == 2 and not (tmp_path / "v.html").exists() and len(stderr.strip().splitlines()) == 1
    assert (
        "trajectory joints ['theta1', 'd2', 'd3', 'theta4', 'theta5'] are not the robot's ['panda_joint1'"
        in stderr
    )
    # given the robot, it draws
    code, stdout, _ = run(["show", str(moved), "--html", str(tmp_path / "v.html"), "--urdf", "cpr"], capsys)
    assert code == 0 and "wrote" in stdout and (tmp_path / "v.html").stat().st_size > 0


@pytest.mark.slow
def test_a_plan_prints_no_third_party_warning(tmp_path: Path) -> None:
    # a URDF urdfdom complains about (a material without a colour), every warning shown
    grey = '<material name="base_grey"><color rgba="0.35 0.35 0.38 1"/></material>'
    (tmp_path / "robot.urdf").write_text(
        ck.cpr_urdf_path().read_text().replace(grey, '<material name="base_grey"></material>')
    )
    scene = write_scene(
        tmp_path, {**with_changes(planner={"seed": 1, "fireflies": 10}), "robot": "robot.urdf"}
    )
    done = subprocess.run(
        [sys.executable, "-m", "planning.cli", "plan", str(scene), "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONWARNINGS": "default"},
        check=False,
    )
    assert done.returncode == 0 and done.stderr == ""


@pytest.mark.parametrize(
    ("duration", "ends", "least"),
    [(0.05, "rest", "1.62 s"), (1.0, "rest", "1.62 s"), (0.5, "natural", "1.12 s")],
)
def test_a_duration_too_short_for_the_limits_exits_2_naming_the_least(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], duration: float, ends: str, least: str
) -> None:
    scene = write_scene(tmp_path, with_changes(duration=duration, spline={"ends": ends}))
    code, _, stderr = run(["plan", str(scene), "--out", str(tmp_path / "out")], capsys)
    assert code == 2 and not (tmp_path / "out").exists()
    assert f"duration = {duration:g} s is shorter than the least time the joint limits allow" in stderr
    assert f"{least} (joint 'theta1' moves 1.68 rad" in stderr and f"give at least {least}" in stderr


def test_names_a_terminal_would_obey_are_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    document = with_changes(name="evil\u202etxt", obstacles__0__name="crate\x1b[2J")
    scene = write_scene(tmp_path, yaml.safe_dump(document, allow_unicode=True))
    code, _, stderr = run(["plan", str(scene), "--out", str(tmp_path / "out")], capsys)
    assert code == 2 and stderr.count("\n") == 1
    assert "name = 'evil\\u202etxt': holds U+202E (RIGHT-TO-LEFT OVERRIDE)" in stderr
    assert "obstacles[0].name = 'crate\\x1b[2J': holds U+001B" in stderr
    assert "\u202e" not in stderr and "\x1b" not in stderr


def test_a_file_name_a_terminal_would_obey_is_printed_escaped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = write_scene(tmp_path, "start: [", name="odd\u202eyaml.yaml")
    code, _, stderr = run(["plan", str(scene), "--out", str(tmp_path / "out")], capsys)
    assert code == 2 and "odd\\u202eyaml.yaml" in stderr and "\u202e" not in stderr
