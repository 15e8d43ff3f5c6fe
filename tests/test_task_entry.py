"""A scene file's ``task:``: read into the segments of planning.task, written back, and refused when wrong."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest
import yaml

from planning.errors import SceneError
from planning.io.scene_file import load_scene, load_scene_file, parse_scene_file, scene_document
from planning.pipeline.target import Target
from planning.task import Attach, Detach, Move, ToolLine, Wait

PICK = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "pick_and_place.yaml"

BASE: dict[str, Any] = {
    "start": {"q": [0.3, 0.3, 0.25, 0.2, 0.5]},
    "task": [{"line": {"by": [0.0, 0.0, 0.05], "frame": "base"}}, {"wait": 0.2}],
}


def with_task(*entries: Any, **keys: Any) -> dict[str, Any]:
    document = copy.deepcopy(BASE)
    document["task"] = list(entries)
    document.update(keys)
    return document


def test_the_example_task_reads_as_its_segments() -> None:
    read = load_scene_file(PICK)
    kinds = [type(s) for s in read.task]
    assert kinds == [Move, ToolLine, Wait, Attach, ToolLine, Move, Detach, ToolLine]
    move, down, wait, attach = read.task[:4]
    assert isinstance(move, Move) and move.goal == Target(tcp=(-0.1, 0.55, 0.45))
    assert isinstance(down, ToolLine) and down.by == (0.0, 0.0, -0.08) and down.offset_frame == "base"
    assert isinstance(wait, Wait) and wait.seconds == 0.3
    assert isinstance(attach, Attach) and attach.payload.mass_kg == 1.5 and attach.payload.name == "part"
    assert attach.payload.shape is None  # it takes the obstacle 'part' (planning.task.holding)
    assert any(
        o.name == "part" and o.touch_links == ("tool_link", "wrist_link") for o in read.scene.obstacles
    )
    assert read.scene.goal == read.scene.start  # a task's scene: its segments say where it goes


def test_a_task_written_back_reads_as_the_same_task() -> None:
    read = load_scene_file(PICK)
    document = yaml.safe_load(yaml.safe_dump(scene_document(read.scene, read.task)))
    assert "goal" not in document
    again = parse_scene_file(document, "again", PICK.parent)
    assert again.task == read.task and again.scene == read.scene


def test_a_line_to_a_pose_reads_its_quaternion_or_rpy() -> None:
    to = {"xyz": [0.4, 0.2, 0.3], "rpy": [3.141592653589793, 0.0, 0.0]}
    read = parse_scene_file(with_task({"line": {"to": to, "tolerance": {"position_m": 2e-4}}}))
    line = read.task[0]
    assert isinstance(line, ToolLine) and line.to is not None and line.by is None
    assert line.to.xyz == (0.4, 0.2, 0.3)
    assert abs(abs(line.to.quat_xyzw[0]) - 1.0) < 1e-12  # a half turn about x
    assert line.tolerance.position_m == 2e-4 and line.tolerance.angle_rad == 0.01


def test_every_option_of_a_line_and_a_constraint_is_written_back_as_read() -> None:
    # the entries a task's file holds must read as the task planned: check re-reads them
    to = {"xyz": [0.4, 0.2, 0.3], "quat_xyzw": [1.0, 0.0, 0.0, 0.0]}
    held = {"axes": ["x", "y", "z"], "angle_rad": 0.02, "quat_xyzw": [0, 0, 0, 1], "frame": "tool_link"}
    entries = [
        {"line": {"to": to, "tool_frame": "wrist_link", "tool_speed_m_s": 0.05}},
        {"line": {"by": [0.0, 0.01, 0.0], "tolerance": {"position_m": 3e-4, "angle_rad": 0.02}}},
        {"move": {"tcp": [0.4, 0.2, 0.35], "constraint": held}},
    ]
    read = parse_scene_file(with_task(*entries))
    first, second, third = read.task
    assert isinstance(first, ToolLine) and first.frame == "wrist_link" and first.tool_speed_m_s == 0.05
    assert first.to is not None and first.to.xyz == (0.4, 0.2, 0.3)
    assert isinstance(second, ToolLine) and second.offset_frame == "tool" and second.to is None
    assert second.tolerance.position_m == 3e-4 and second.tolerance.angle_rad == 0.02
    assert isinstance(third, Move) and third.constraint is not None and third.constraint.frame == "tool_link"
    document = yaml.safe_load(yaml.safe_dump(scene_document(read.scene, read.task)))
    assert document["task"][0]["line"]["tool_frame"] == "wrist_link"
    assert parse_scene_file(document).task == read.task


def test_load_scene_refuses_a_task_and_says_how_to_plan_it() -> None:
    with pytest.raises(SceneError, match=r"holds a task of 8 segments.*cpr-plan plan"):
        load_scene(PICK)


BAD: list[tuple[str, dict[str, Any], str]] = [
    ("goal and task", {**BASE, "goal": {"tcp": [0.4, 0.2, 0.3]}}, r"exactly one of 'goal' .* or 'task'"),
    ("neither", {"start": BASE["start"]}, r"exactly one of 'goal' .* or 'task'"),
    ("empty task", with_task(), r"task: 0 items; needs at least 1"),
    ("duration", with_task({"wait": 1.0}, duration=3.0), r"duration = 3 s: a task times each"),
    ("two keys", with_task({"wait": 1.0, "detach": {}}), r"task\[0\]: an entry of task has exactly one key"),
    (
        "unknown key",
        with_task({"jump": 1.0}),
        r"task\[0\]\.jump: unknown key; allowed here: move, line, wait",
    ),
    (
        "unknown line key",
        with_task({"line": {"by": [0, 0, 0.1], "speed": 1}}),
        r"task\[0\]\.line\.speed: unknown key; allowed here: to, by, frame, tool_frame",
    ),
    (
        "zero line",
        with_task({"line": {"by": [0, 0, 0]}}),
        r"task\[0\]\.line: by = \[0.0, 0.0, 0.0\] m .*zero",
    ),
    ("no end", with_task({"line": {"frame": "base"}}), r"task\[0\]\.line: give exactly one of 'to'"),
    (
        "frame with to",
        with_task({"line": {"to": {"xyz": [0.4, 0.2, 0.3], "rpy": [0, 0, 0]}, "frame": "base"}}),
        r"'frame' is the frame of 'by'",
    ),
    (
        "bad frame",
        with_task({"line": {"by": [0, 0, 0.1], "frame": "world"}}),
        r"task\[0\]\.line\.frame = 'world'",
    ),
    (
        "tolerance",
        with_task({"line": {"by": [0, 0, 0.1], "tolerance": {"position_m": 0.5}}}),
        r"task\[0\]\.line\.tolerance\.position_m = 0\.5",
    ),
    ("long wait", with_task({"wait": 7200}), r"task\[0\]\.wait = 7200"),
    (
        "detach nothing",
        with_task({"wait": 1.0}, {"detach": {}}),
        r"task\[1\]\.detach: the robot carries nothing",
    ),
    (
        "attach twice",
        with_task({"attach": {"name": "a", "mass_kg": 1}}, {"attach": {"name": "b", "mass_kg": 1}}),
        r"task\[1\]\.attach: the robot already carries 'a' here; detach it first",
    ),
    (
        "detach another",
        with_task({"attach": {"name": "a", "mass_kg": 1}}, {"detach": {"name": "b"}}),
        r"task\[1\]\.detach\.name = 'b', but the robot carries 'a' here",
    ),
    (
        "heavy part",
        with_task({"attach": {"mass_kg": 5000}}),
        r"task\[0\]\.attach\.mass_kg = 5000",
    ),
]


@pytest.mark.parametrize(("label", "document", "message"), BAD, ids=[b[0] for b in BAD])
def test_a_bad_task_is_refused_naming_the_entry_and_the_field(
    label: str, document: dict[str, Any], message: str
) -> None:
    with pytest.raises(SceneError, match=message):
        parse_scene_file(document, "scene.yaml")


def test_detaching_the_scenes_own_payload_is_allowed() -> None:
    document = with_task({"detach": {"name": "tool"}}, payload={"name": "tool", "mass_kg": 0.5})
    assert parse_scene_file(document).task == (Detach("tool"),)


def test_the_formats_documents_task_reads_as_written() -> None:
    formats = (Path(__file__).resolve().parents[1] / "docs" / "formats.md").read_text()
    block = next(b for b in formats.split("```yaml\n")[1:] if b.startswith("task:")).split("```")[0]
    read = parse_scene_file({"start": BASE["start"], **yaml.safe_load(block)})
    kinds = [type(s) for s in read.task]
    assert kinds == [Move, Move, ToolLine, ToolLine, Wait, Attach, Detach]
    upright = read.task[1]
    assert (
        isinstance(upright, Move) and upright.constraint is not None and upright.constraint.axes == ("x", "y")
    )
    line = read.task[3]
    assert isinstance(line, ToolLine) and line.tool_speed_m_s == 0.1 and line.frame == "tcp"


def test_a_move_may_keep_the_tool_upright_and_reads_back_the_same() -> None:
    upright = {"axes": ["y", "x"], "angle_rad": 0.05, "rpy": [3.141592653589793, 0.0, 0.0]}
    read = parse_scene_file(with_task({"move": {"tcp": [0.4, 0.2, 0.3], "constraint": upright}}))
    move = read.task[0]
    assert isinstance(move, Move) and move.constraint is not None
    assert move.constraint.axes == ("x", "y") and move.constraint.angle_rad == 0.05
    assert move.constraint.quat_xyzw is not None and abs(abs(move.constraint.quat_xyzw[0]) - 1.0) < 1e-12
    default = parse_scene_file(with_task({"move": {"tcp": [0.4, 0.2, 0.3], "constraint": {}}})).task[0]
    assert isinstance(default, Move) and default.constraint is not None
    assert default.constraint.axes == ("x", "y") and default.constraint.quat_xyzw is None  # the start's
    document = scene_document(read.scene, read.task)
    assert parse_scene_file(yaml.safe_load(yaml.safe_dump(document))).task == read.task


BAD_CONSTRAINTS: list[tuple[dict[str, Any], str]] = [
    ({"axes": ["x"]}, r"task\[0\]\.move\.constraint\.axes: 1 item; needs at least 2"),
    ({"axes": ["x", "x"]}, r"task\[0\]\.move\.constraint: axes = \['x', 'x'\] names an axis twice"),
    ({"axes": ["x", "w"]}, r"task\[0\]\.move\.constraint\.axes\[1\] = 'w'"),
    ({"angle_rad": 1.0}, r"task\[0\]\.move\.constraint\.angle_rad = 1"),
    ({"rpy": [0, 0, 0], "quat_xyzw": [0, 0, 0, 1]}, r"give at most one of 'quat_xyzw' and 'rpy'"),
    ({"quat_xyzw": [0, 0, 0, 0]}, r"task\[0\]\.move\.constraint\.quat_xyzw"),
    (
        {"roll": 0.1},
        r"task\[0\]\.move\.constraint\.roll: unknown key; allowed here: axes, angle_rad, quat_xyzw",
    ),
]


@pytest.mark.parametrize(("constraint", "message"), BAD_CONSTRAINTS, ids=[m for _, m in BAD_CONSTRAINTS])
def test_a_bad_constraint_is_refused_naming_its_field(constraint: dict[str, Any], message: str) -> None:
    with pytest.raises(SceneError, match=message):
        parse_scene_file(with_task({"move": {"tcp": [0.4, 0.2, 0.3], "constraint": constraint}}))
