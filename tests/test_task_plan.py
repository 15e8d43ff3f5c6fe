"""A task on the CPR among the shelf's obstacles: move, lower the tool, wait, lift it, move on.

Checked independently of the planner's own verification: the segments tile the trajectory,
the robot is at rest (velocity, acceleration and jerk zero) where it waits and at the ends,
it stands still while it waits, it passes a junction without stopping only where that is
sooner, the jerk is continuous at every knot (left and right limits), and the tool stays on
each line every millisecond (Pinocchio's forward kinematics).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from planning.errors import PlanningError, TaskSegmentError, ToolLineBrokenError
from planning.io.scene_file import load_scene
from planning.pipeline.planner import solve
from planning.pipeline.problem import build_problem
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.pipeline.timing import FreeDuration
from planning.task import Attach, Detach, Move, TaskMotion, ToolLine, Wait, plan_task

SHELF = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "shelf.yaml"


@pytest.fixture(scope="module")
def shelf() -> Scene:
    return load_scene(SHELF)


@pytest.fixture(scope="module")
def task(shelf: Scene) -> TaskMotion:
    return plan_task(
        shelf,
        [
            Move(Target(tcp=(-0.1, 0.55, 0.45))),
            ToolLine(by=(0.0, 0.0, -0.08), offset_frame="base"),
            Wait(0.3),
            ToolLine(by=(0.0, 0.0, 0.08), offset_frame="base"),
            Move(shelf.goal),
        ],
    )


def test_the_segments_tile_the_trajectory_at_rest_where_the_task_waits(task: TaskMotion) -> None:
    trajectory = task.trajectory
    assert [s.kind for s in task.segments] == ["free", "line", "wait", "line", "free"]
    assert task.segments[0].t0 == 0.0 and task.segments[-1].t1 == pytest.approx(trajectory.duration)
    for before, after in zip(task.segments[:-1], task.segments[1:], strict=True):
        assert before.t1 == pytest.approx(after.t0, abs=1e-12)
    still = [0.0, task.segments[2].t0, task.segments[2].t1, trajectory.duration]  # the wait, the ends
    for t in still:
        for r in (1, 2, 3):
            assert (
                np.abs(trajectory(np.clip(t + np.array([-1e-9, 1e-9]), 0.0, trajectory.duration), r)).max()
                < 1e-5
            )
    wait = task.segments[2]
    held = trajectory(np.linspace(wait.t0, wait.t1, 50))
    assert np.abs(held - held[0]).max() <= 1e-12
    assert task.accepted, task.problems
    assert all(s.verification is not None and s.verification.accepted for s in task.segments)


WAIT_S = 1e-3
"""A wait short enough to leave a task's timing as it is, but for a stop at each junction [s]."""


def stopping_at_every_junction(segments: list[Move | ToolLine | Wait]) -> list[Move | ToolLine | Wait]:
    """``segments`` with a wait of :data:`WAIT_S` between two that move: the robot stops at each junction."""
    stopping: list[Move | ToolLine | Wait] = []
    for segment in segments:
        if stopping and not isinstance(segment, Wait) and not isinstance(stopping[-1], Wait):
            stopping.append(Wait(WAIT_S))
        stopping.append(segment)
    return stopping


OUT_AND_ON = {
    "out and back": ((0.0, 0.3, 0.3, 0.0, 0.0), (1.0, 0.4, 0.4, 0.0, 0.0), (0.0, 0.3, 0.3, 0.0, 0.0)),
    "out and on": ((0.0, 0.3, 0.3, 0.0, 0.0), (1.0, 0.4, 0.4, 0.0, 0.0), (2.0, 0.5, 0.5, 0.0, 0.0)),
}


@pytest.mark.parametrize("way", list(OUT_AND_ON))
def test_a_task_never_takes_longer_than_stopping_at_its_junctions(shelf: Scene, way: str) -> None:
    """Passing a junction without stopping is chosen only where it is sooner (a turn back is not).

    The oracle: the same task with a wait of 1 ms between its motions, so that the robot stops
    at each junction; less the waits, it takes as long as the task may at most.
    """
    start, middle, end = OUT_AND_ON[way]
    scene = dataclasses.replace(shelf, obstacles=(), start=Target(q=start), goal=Target(q=end), duration=None)
    segments: list[Move | ToolLine | Wait] = [Move(Target(q=middle)), Move(Target(q=end))]
    passing = plan_task(scene, segments)
    stopping = plan_task(scene, stopping_at_every_junction(segments))
    assert passing.accepted and stopping.accepted
    assert passing.trajectory.duration <= stopping.trajectory.duration - WAIT_S + 1e-9


def test_the_shelf_task_takes_no_longer_than_stopping_at_its_junctions(
    shelf: Scene, task: TaskMotion
) -> None:
    segments: list[Move | ToolLine | Wait] = [
        Move(Target(tcp=(-0.1, 0.55, 0.45))),
        ToolLine(by=(0.0, 0.0, -0.08), offset_frame="base"),
        Wait(0.3),
        ToolLine(by=(0.0, 0.0, 0.08), offset_frame="base"),
        Move(shelf.goal),
    ]
    stopping = plan_task(shelf, stopping_at_every_junction(segments))
    waits = len(stopping.segments) - len(task.segments)
    assert task.trajectory.duration <= stopping.trajectory.duration - waits * WAIT_S + 1e-9


def test_the_jerk_is_continuous_at_every_knot(task: TaskMotion) -> None:
    trajectory = task.trajectory
    inner = trajectory.knots[1:-1]
    left, right = trajectory(inner - 1e-9, 3), trajectory(inner + 1e-9, 3)
    assert np.abs(left - right).max() < 1e-3 * np.abs(trajectory.extrema(3).peak).max()


def test_the_tool_stays_on_each_line_every_millisecond(task: TaskMotion) -> None:
    robot = ck.load_cpr()
    model, data = robot.model, robot.model.createData()
    fid = model.getFrameId(robot.tcp_frame)
    for segment, lift in zip((s for s in task.segments if s.kind == "line"), (-0.08, 0.08), strict=True):
        assert segment.line is not None
        start, goal = segment.line.start.placement(), segment.line.goal.placement()
        shift = goal.translation - start.translation
        for q in task.trajectory(np.arange(segment.t0, segment.t1, 1e-3)):
            pin.framesForwardKinematics(model, data, q)
            point = data.oMf[fid].translation
            sigma = np.clip((point - start.translation) @ shift / (shift @ shift), 0.0, 1.0)
            assert np.linalg.norm(point - start.translation - sigma * shift) <= 1e-3
        np.testing.assert_allclose(shift, [0.0, 0.0, lift], atol=1e-9)


def test_a_free_motion_asked_to_end_still_in_jerk_does(shelf: Scene) -> None:
    problem = build_problem(shelf)
    free = solve(problem).trajectory
    assert np.abs(free(free.knots[-1], 3)).max() > 1e-3  # the planner's own ends move in jerk
    assert isinstance(problem.duration, FreeDuration)
    still = dataclasses.replace(problem.duration, still_jerk=True)
    trajectory = solve(dataclasses.replace(problem, duration=still)).trajectory
    for r in (1, 2, 3):
        assert np.abs(trajectory(trajectory.knots[[0, -1]], r)).max() < 1e-9


def test_bad_tasks_are_refused_naming_the_segment(shelf: Scene) -> None:
    with pytest.raises(PlanningError, match="at least one segment"):
        plan_task(shelf, [])
    with pytest.raises(PlanningError, match=r"the scene fixes duration = 4 s; .* leave the duration out"):
        plan_task(dataclasses.replace(shelf, duration=4.0), [Wait(0.1)])
    with pytest.raises(PlanningError, match=r"wait seconds = 0 s must be a number in \(0, 3600\] s"):
        Wait(0)
    inside = Target(tcp=(0.35, 0.35, 0.15))  # in the crate
    with pytest.raises(PlanningError, match=r"task\[1\] \(move\): "):
        plan_task(shelf, [Wait(0.1), Move(inside)])


def test_a_line_that_breaks_in_a_task_names_its_segment_and_share(shelf: Scene) -> None:
    with pytest.raises(TaskSegmentError, match=r"task\[1\] \(line\): the tool line breaks after") as err:
        plan_task(shelf, [Wait(0.1), ToolLine(by=(0.0, 0.0, -0.5), offset_frame="base")])
    assert err.value.segment == 1
    assert isinstance(err.value.cause, ToolLineBrokenError) and 0.0 < err.value.cause.fraction < 1.0


def test_an_attached_part_adds_its_weight_to_the_vertical_axis_and_its_shape_to_the_checks(
    shelf: Scene,
) -> None:
    part = ck.Payload(
        mass_kg=1.5,
        shape=ck.Obstacle.box(size=(0.04, 0.04, 0.04), xyz=(0.0, 0.0, 0.03)),
        touch_links=("tool_link",),
        name="part",
    )
    above = Move(Target(tcp=(-0.1, 0.55, 0.45)))
    down = ToolLine(by=(0.0, 0.0, -0.08), offset_frame="base")
    task = plan_task(shelf, [above, down, Wait(0.2), Attach(part), Wait(0.2), Move(shelf.goal), Detach()])
    assert task.accepted, task.problems
    assert [s.kind for s in task.segments] == ["free", "line", "wait", "attach", "wait", "free", "detach"]
    assert task.segments[3].t0 == task.segments[3].t1 == task.segments[2].t1  # an attach takes no time
    held = []
    for wait in (task.segments[2], task.segments[4]):
        assert wait.verification is not None and wait.verification.torques is not None
        held.append(float(np.median(wait.verification.torques.torques[:, 1])))  # d2, the vertical axis [N]
    assert held[1] - held[0] == pytest.approx(1.5 * 9.81, rel=1e-3)  # the part's weight, m g
    ball = ck.Payload(
        mass_kg=0.5, shape=ck.Obstacle.sphere(0.25, (0.0, 0.0, 0.0)), touch_links=("tool_link",)
    )
    with pytest.raises(PlanningError, match=r"task\[3\] \(attach\): .* from obstacle 'pipe'"):
        plan_task(shelf, [above, down, Wait(0.2), Attach(ball)])


def test_attach_and_detach_out_of_turn_are_refused(shelf: Scene) -> None:
    with pytest.raises(PlanningError, match=r"task\[1\] \(detach\): detach: the robot carries nothing here"):
        plan_task(shelf, [Wait(0.1), Detach()])
    part = ck.Payload(mass_kg=0.2, name="part")
    with pytest.raises(
        PlanningError, match=r"task\[1\] \(attach\): attach: the robot already carries 'part'"
    ):
        plan_task(shelf, [Attach(part), Attach(part)])
