"""``cpr-plan robot-info``: the robot of a scene file is the one a plan of that file loads."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from planning.cli import main
from planning.io.scene_file import load_scene

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "scenes"


@pytest.mark.parametrize("name", ["panda_post.yaml", "shelf.yaml"])
def test_a_scene_files_robot_is_the_one_its_plan_loads(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    # it read a scene file as a URDF: "is not well-formed XML: Start tag expected"
    path = EXAMPLES / name
    assert main(["robot-info", str(path), "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    robot = load_scene(path).robot_spec().load()  # the oracle: what `cpr-plan plan` loads
    assert Path(report["urdf"]) == robot.urdf_path and report["tcp_frame"] == robot.tcp_frame
    assert [j["name"] for j in report["joints"]] == list(robot.joint_names)


def test_the_bundled_robot_with_another_tool_frame_is_the_one_a_scene_of_it_loads(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # `robot-info cpr --tcp ...` was refused while a scene could name that robot
    scene = tmp_path / "scene.yaml"
    ends = "start: {q: [0, 0.3, 0.3, 0, 0]}\ngoal: {q: [1, 0.3, 0.3, 0, 0]}\n"
    scene.write_text("robot: {urdf: cpr, tcp: tool_link}\n" + ends)
    assert main(["robot-info", "cpr", "--tcp", "tool_link", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    robot = load_scene(scene).robot_spec().load()  # the oracle: what `cpr-plan plan` loads
    assert report["tcp_frame"] == robot.tcp_frame == "tool_link" and Path(report["urdf"]) == robot.urdf_path
    assert [j["name"] for j in report["joints"]] == list(robot.joint_names)


def test_a_bad_scene_file_is_one_line_naming_the_field(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scene = tmp_path / "scene.yml"
    scene.write_text("robot: panda\nstart: {q: [0, 0, 0]}\ngoal: {q: [0, 0, 0]}\nsafety_margin: -1\n")
    assert main(["robot-info", str(scene)]) == 2
    error = capsys.readouterr().err
    assert "safety_margin" in error and error.count("\n") == 1 and "Traceback" not in error
