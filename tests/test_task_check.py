"""A task's trajectory held to its task (what ``cpr-plan check`` verifies): broken promises are named."""

from __future__ import annotations

import copy
import dataclasses

import pytest

import cpr_kin as ck
from planning.errors import PlanningError
from planning.io.scene_file import SceneFile
from planning.pipeline import hulls_first
from planning.pipeline import verification as verification_module
from planning.pipeline.target import Target
from planning.pipeline.verification import Requirements, Verification
from planning.task import Attach, Move, TaskMotion, ToolLine, Wait, check_task, task_record

from .conftest import PlannedTask


@pytest.fixture(scope="module")
def read(pick_and_place: PlannedTask) -> SceneFile:
    return pick_and_place.read


@pytest.fixture(scope="module")
def task(pick_and_place: PlannedTask) -> TaskMotion:
    return pick_and_place.task


def test_the_planned_task_passes_its_check_with_the_planners_clearance(
    read: SceneFile, task: TaskMotion
) -> None:
    checked = check_task(read.scene, read.task, task.trajectory, task_record(task))
    assert checked.accepted, checked.problems
    assert checked.certified_min_clearance_m == pytest.approx(task.certified_min_clearance_m, abs=1e-9)
    assert checked.checks > 100
    moving = [v for v in checked.verifications if v is not None]
    assert len(moving) == 6  # two free motions, three lines, a wait


def test_a_record_of_another_task_is_refused_segment_by_segment(read: SceneFile, task: TaskMotion) -> None:
    record = task_record(task)
    shorter = check_task(read.scene, read.task[:-1], task.trajectory, record)
    assert shorter.problems == (
        "the trajectory's task is ['free', 'line', 'wait', 'attach', 'line', 'free', 'detach', 'line']; "
        "the scene's is ['free', 'line', 'wait', 'attach', 'line', 'free', 'detach']",
    )
    renamed = copy.deepcopy(record)
    renamed[3]["object"] = "bolt"
    found = check_task(read.scene, read.task, task.trajectory, renamed).problems
    assert found == ("task[3] (attach) names 'bolt', not 'part'",)


def test_a_task_asking_other_waits_goals_and_lines_fails(read: SceneFile, task: TaskMotion) -> None:
    record, segments = task_record(task), list(read.task)
    segments[2] = Wait(0.5)
    segments[5] = Move(Target(tcp=(-0.2, 0.6, 0.30)))  # 5 cm below where the planned motion went
    down = segments[1]
    assert isinstance(down, ToolLine)
    segments[1] = dataclasses.replace(down, by=(0.0, 0.0, -0.1))
    found = check_task(read.scene, segments, task.trajectory, record).problems
    assert any(p.startswith("task[2] (wait) waits 0.3 s; the task's wait is 0.5 s") for p in found)
    assert any(p.startswith("task[5] (free) its goal is") for p in found)
    assert any(p.startswith("task[1] (line) records its 'to' pose 0.02 m") for p in found)


def test_a_heavier_part_than_the_motion_was_timed_for_is_caught_by_the_torques(
    read: SceneFile, task: TaskMotion
) -> None:
    attach = read.task[3]
    assert isinstance(attach, Attach)
    heavy = Attach(dataclasses.replace(attach.payload, mass_kg=150.0))
    segments = (*read.task[:3], heavy, *read.task[4:])
    found = check_task(read.scene, segments, task.trajectory, task_record(task)).problems
    assert found and all(p.startswith(("task[4]", "task[5]")) for p in found)
    assert any("beyond its effort limit" in p for p in found)


def test_an_obstacle_on_the_line_fails_that_segment(read: SceneFile, task: TaskMotion) -> None:
    line = task.segments[1]
    assert line.line is not None
    middle = tuple((a + b) / 2 for a, b in zip(line.line.start.xyz, line.line.goal.xyz, strict=True))
    ball = ck.Obstacle.sphere(0.02, middle, name="ball")
    scene = dataclasses.replace(read.scene, obstacles=(*read.scene.obstacles, ball))
    found = check_task(scene, read.task, task.trajectory, task_record(task)).problems
    assert any(p.startswith("task[1] (line)") and "ball" in p for p in found)


def test_check_tries_the_step_each_entry_records_first(
    read: SceneFile, task: TaskMotion, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Where the scene's step cannot certify a segment, its entry's ``certified_step`` is tried next,
    and the planner's finer steps (the hulls' problem on a robot of meshes) are not built."""
    accepted = next(
        v for v in check_task(read.scene, read.task, task.trajectory, task_record(task)).verifications if v
    )
    record, recorded_m = task_record(task), 0.0003
    for entry in record:
        if entry["kind"] in ("free", "line", "wait"):
            entry["certified_step"] = recorded_m
    tried: list[float] = []

    def certifies_at_the_recorded_step(
        world: ck.CollisionWorld, trajectory: object, required: Requirements
    ) -> Verification:
        step_m = required.step_m
        tried.append(step_m)
        return accepted if step_m <= recorded_m else dataclasses.replace(accepted, problems=("too coarse",))

    def not_built(problem: object) -> object:
        raise AssertionError("the planner's finer steps were built")

    monkeypatch.setattr(verification_module, "verify_trajectory", certifies_at_the_recorded_step)
    monkeypatch.setattr(hulls_first, "finer_steps_m", not_built)
    checked = check_task(read.scene, read.task, task.trajectory, record)
    assert checked.accepted, checked.problems
    assert tried == [read.scene.planner.verify_step_m, recorded_m] * 6  # six segments move or wait


@pytest.mark.parametrize("step", ["5 mm", 0.0, 2.0, False])
def test_a_recorded_step_check_could_not_take_names_its_entry(
    read: SceneFile, task: TaskMotion, step: object
) -> None:
    record = task_record(task)
    record[1]["certified_step"] = step
    with pytest.raises(PlanningError) as info:
        check_task(read.scene, read.task, task.trajectory, record)
    assert str(info.value).startswith(
        f"task entry 1: certified_step = {step!r} is not a step in [0.0001, 0.1] m"
    )
