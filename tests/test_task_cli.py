"""``cpr-plan`` on a scene file with a task: plan, check, show, export, and bad tasks refused."""

from __future__ import annotations

import base64
import copy
import itertools
import json
import re
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

import cpr_kin as ck
from planning.cli import main
from planning.io.trajectory_reader import read_trajectory

PICK = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "pick_and_place.yaml"


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    captured = capsys.readouterr()
    return code, captured.out, captured.err


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("task") / "out"
    assert main(["plan", str(PICK), "--out", str(out)]) == 0
    return out


def test_a_task_plans_into_one_file_that_says_what_it_promised(planned: Path) -> None:
    document = json.loads((planned / "trajectory.json").read_text())
    task = document["task"]
    assert [e["kind"] for e in task] == ["free", "line", "wait", "attach", "line", "free", "detach", "line"]
    assert task[0]["t0"] == 0.0 and task[-1]["t1"] == document["knots"][-1]
    for before, after in itertools.pairwise(task):
        assert before["t1"] == after["t0"]
    down = task[1]
    assert set(down) == {"kind", "t0", "t1", "frame", "from", "to", "tolerance", "certified_step"}
    assert down["tolerance"] == {"position_m": 0.001, "angle_rad": 0.01}
    np.testing.assert_allclose(np.subtract(down["to"]["xyz"], down["from"]["xyz"]), [0, 0, -0.08], atol=1e-12)
    for released in (task[3], task[6]):
        assert released["object"] == "part" and released["frame"] == "tcp"
    assert [list(e) for e in document["scene"]["task"]][3] == ["attach"] and "goal" not in document["scene"]
    # the file's own numbers: where the tool is at the line's ends, by Pinocchio
    trajectory = read_trajectory(planned / "trajectory.json").trajectory
    robot = ck.load_cpr()
    for key, t in (("from", down["t0"]), ("to", down["t1"])):
        np.testing.assert_allclose(ck.frame_positions(robot, trajectory(t)), down[key]["xyz"], atol=1e-3)
    samples = (planned / "samples.csv").read_text().splitlines()
    assert samples[0].startswith("t,theta1") and len(samples) > 300  # every 12 ms over 4.5 s
    assert "| 3 | attach 'part' |" in (planned / "report.md").read_text()


def test_a_task_planned_with_json_and_plots_says_what_it_wrote(
    planned: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "drawn"
    code, stdout, _ = run(["plan", str(PICK), "--out", str(out), "--json", "--plots"], capsys)
    assert code == 0
    summary = json.loads(stdout)
    assert summary["status"] == "ok" and summary["accepted"] and summary["segments"] == 8
    assert [entry["kind"] for entry in summary["task"]] == [
        entry["kind"] for entry in json.loads((planned / "trajectory.json").read_text())["task"]
    ]
    written = {Path(p).name for p in summary["outputs"]}
    assert {"trajectory.json", "joints.png", "tcp_path.png"} <= written
    assert all((out / name).stat().st_size > 0 for name in written)
    # the summary's numbers are the file's: same seed, same task
    document = json.loads((out / "trajectory.json").read_text())
    assert summary["duration"] == document["knots"][-1] == document["metrics"]["duration"]
    assert (out / "trajectory.json").read_bytes() == (planned / "trajectory.json").read_bytes()


def test_check_verifies_a_task_and_names_a_broken_promise(
    planned: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    trajectory = planned / "trajectory.json"
    code, stdout, _ = run(["check", str(PICK), str(trajectory)], capsys)
    assert code == 0 and "a task of 8 segments" in stdout and "every line within its tolerance" in stdout
    document = json.loads(trajectory.read_text())
    tampered = copy.deepcopy(document)
    tampered["task"][4]["to"]["xyz"][0] += 0.004  # the lift the file names is 4 mm off the one followed
    path = tmp_path / "tampered.json"
    path.write_text(json.dumps(tampered))
    code, stdout, _ = run(["check", str(PICK), str(path), "--json"], capsys)
    verdict = json.loads(stdout)
    assert code == 3 and verdict["status"] == "failed"
    assert any(p.startswith("task[4] (line) records its 'to' pose 0.004 m") for p in verdict["problems"])
    assert any(p.startswith("task entry 4 (line) leaves its line by") for p in verdict["problems"])
    steps = [entry.get("certified_step") for entry in document["task"]]  # attach and detach: none
    assert verdict["certified_steps_m"] == steps and steps.count(None) == 2
    shelf = PICK.parent / "shelf.yaml"
    code, _, err = run(["check", str(shelf), str(trajectory)], capsys)
    assert code == 2 and "holds no task: check it against the scene file that holds the task" in err


def test_show_prints_the_timeline_and_export_takes_the_task(
    planned: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    page = tmp_path / "viewer.html"
    code, stdout, _ = run(["show", str(planned / "trajectory.json"), "--html", str(page)], capsys)
    assert code == 0 and page.stat().st_size > 10_000
    drawn = b"".join(base64.b64decode(m) for m in re.findall(r"base64,([A-Za-z0-9+/=]+)", page.read_text()))
    assert b"scene/carried/part" in drawn  # the obstacle the task takes: drawn as what it carries, once
    assert b"scene/obstacles/part" not in drawn and b"scene/obstacles/crate" in drawn
    lines = stdout.splitlines()
    assert (
        lines[0] == "task:"
        and "attach 'part' at tcp" in lines[4]
        and lines[2].endswith("line of tcp, within {'position_m': 0.001, 'angle_rad': 0.01}")
    )
    out = tmp_path / "trajectory.yaml"
    code, _, _ = run(
        ["export", str(planned / "trajectory.json"), "--format", "joint-trajectory", "--out", str(out)],
        capsys,
    )
    exported = yaml.safe_load(out.read_text())
    duration = json.loads((planned / "trajectory.json").read_text())["knots"][-1]
    last = exported["points"][-1]["time_from_start"]
    assert code == 0 and last["sec"] + last["nanosec"] * 1e-9 == pytest.approx(duration, abs=1e-9)


BAD: list[tuple[str, dict[str, Any], str, int]] = [
    ("detach of nothing", {"detach": {}}, "task[1].detach: the robot carries nothing here", 2),
    (
        "zero line",
        {"line": {"by": [0, 0, 0]}},
        "task[1].line: by = [0.0, 0.0, 0.0] m is a line of zero length",
        2,
    ),
    ("unknown frame", {"line": {"by": [0, 0, 0.05], "tool_frame": "gripper"}}, "task[1] (line): ", 2),
    (
        "a constraint the start breaks",
        {"move": {"tcp": [-0.2, 0.6, 0.35], "constraint": {"rpy": [1.0, 0.0, 0.0]}}},
        "task[1] (move): the motion's start holds 'tcp' 1 rad from the constraint's orientation",
        2,
    ),
    (
        "a line into the floor",
        {"line": {"by": [0, 0, -1.0], "frame": "base"}},
        "task[1] (line): the tool line breaks after",
        3,
    ),
]


@pytest.mark.parametrize(("label", "entry", "message", "exit_code"), BAD, ids=[b[0] for b in BAD])
def test_a_bad_task_exits_naming_the_segment_and_writes_nothing(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    label: str,
    entry: dict[str, Any],
    message: str,
    exit_code: int,
) -> None:
    document = yaml.safe_load(PICK.read_text())
    document["robot"] = str((PICK.parent / document["robot"]).resolve())
    document["task"] = [{"wait": 0.1}, entry]
    scene = tmp_path / "task.yaml"
    scene.write_text(yaml.safe_dump(document))
    out = tmp_path / "out"
    code, stdout, stderr = run(["plan", str(scene), "--out", str(out)], capsys)
    assert code == exit_code and stdout == "", stderr
    assert message in stderr and "Traceback" not in stderr and len(stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_a_link_an_obstacle_names_that_the_robot_lacks_is_exit_2_and_nothing_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    document = yaml.safe_load(PICK.read_text())
    document["robot"] = str(PICK.parent / document["robot"])
    part = next(o for o in document["obstacles"] if o["name"] == "part")
    part["touch_links"] = ["tool_link", "finger"]
    scene = tmp_path / "typo.yaml"
    scene.write_text(yaml.safe_dump(document))
    code, _, err = run(["plan", str(scene), "--out", str(tmp_path / "out")], capsys)
    assert code == 2 and "Traceback" not in err
    assert "obstacle 'part' touch_links ['finger'] are not links of the robot" in err and "tool_link" in err
    assert not (tmp_path / "out").exists()
