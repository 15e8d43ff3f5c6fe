"""A task's record: plain JSON, one entry per segment, and its promises checked from the record alone."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import pytest

import cpr_kin as ck
from planning.errors import PlanningError
from planning.io.scene_file import load_scene
from planning.pipeline.target import Target
from planning.task import Attach, Move, TaskMotion, ToolLine, Wait, plan_task, record_problems, task_record

SHELF = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "shelf.yaml"


@pytest.fixture(scope="module")
def task() -> TaskMotion:
    scene = load_scene(SHELF)
    part = ck.Payload(mass_kg=0.5, name="part")
    return plan_task(
        scene,
        [
            Move(Target(tcp=(-0.1, 0.55, 0.45))),
            ToolLine(by=(0.0, 0.0, -0.08), offset_frame="base"),
            Wait(0.3),
            Attach(part),
            ToolLine(by=(0.0, 0.0, 0.08), offset_frame="base"),
        ],
    )


def test_the_record_is_plain_json_one_entry_per_segment(task: TaskMotion) -> None:
    record = task_record(task)
    assert json.loads(json.dumps(record)) == record
    assert [e["kind"] for e in record] == ["free", "line", "wait", "attach", "line"]
    assert [(e["t0"], e["t1"]) for e in record] == [(s.t0, s.t1) for s in task.segments]
    line = record[1]
    assert line["frame"] == "tcp" and set(line["tolerance"]) == {"position_m", "angle_rad"}
    assert line["to"]["xyz"][2] == pytest.approx(line["from"]["xyz"][2] - 0.08, abs=1e-12)
    assert record[3]["object"] == "part" and record[3]["frame"] == "tcp"
    steps = [s.verification.check.step_m if s.verification else None for s in task.segments]
    assert [e.get("certified_step") for e in record] == steps  # the attach has none: it does not move
    assert steps[0] == task.scene.planner.verify_step_m


def test_the_promises_hold_and_a_tampered_one_is_caught(task: TaskMotion) -> None:
    robot = ck.load_cpr()
    record = task_record(task)
    assert record_problems(robot, task.trajectory, record) == ()
    moved = copy.deepcopy(record)
    moved[1]["to"]["xyz"][0] += 0.005  # the line the file names is 5 mm off the one followed
    assert any(
        p.startswith("task entry 1 (line) leaves its line by")
        for p in record_problems(robot, task.trajectory, moved)
    )
    stretched = copy.deepcopy(record)
    stretched[2]["t0"] = stretched[1]["t0"]  # a wait over the line's motion
    found = record_problems(robot, task.trajectory, stretched)
    assert any("(wait) moves during" in p for p in found) and any("after the last ended" in p for p in found)
    with pytest.raises(PlanningError, match="task entry 0 has no 't1'"):
        record_problems(robot, task.trajectory, [{"kind": "free", "t0": 0.0}])
    for hostile in ("x", None, True, float("nan"), [0.0]):  # before: an internal error
        with pytest.raises(PlanningError, match=r"task entry 0 't0' = .*; it must be a finite time \[s\]"):
            record_problems(robot, task.trajectory, [{"kind": "free", "t0": hostile, "t1": 1.0}])
