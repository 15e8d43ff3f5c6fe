"""A move's goal before a tool line: of the pose's IK solutions, one from which the line walks."""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning import Scene, build_problem
from planning.errors import TaskSegmentError, ToolLineBrokenError
from planning.io.scene_file import parse_scene_file
from planning.pipeline.verification import Requirements
from planning.task import plan_task
from planning.task.line_goal import LineWalks, line_after
from planning.task.line_motion import line_path
from planning.task.segments import Detach, Move, Wait
from planning.task.tool_line import ToolLine

START = [1.35804, 0.83133, 1.04575, -0.68677, 1.5101, 1.0521, 1.20794]
GOAL_XYZ = [-0.611878, -0.120818, 0.349534]
SCENE = {
    "robot": "panda",
    "start": {"q": START},
    "task": [
        {"move": {"pose": {"xyz": GOAL_XYZ, "rpy": [-2.802611, 0.043693, 0.169956]}}},
        {"line": {"by": [-0.1611, -0.0941, -0.1665], "frame": "base"}},
    ],
    "planner": {"seed": 300},
}
"""A Panda case (generated, seed 300): the IK solution of the goal the arm reaches soonest
drives joint 1 into its limit along this 25 cm line; another branch of the arm walks it."""


@pytest.fixture(scope="module")
def panda() -> ck.Robot:
    return ck.load_robot(example_robot("panda"))


@pytest.fixture(scope="module")
def read() -> tuple[Scene, Move, ToolLine]:
    file = parse_scene_file(SCENE)
    move, line = file.task
    assert isinstance(move, Move) and isinstance(line, ToolLine)
    return file.scene, move, line


@pytest.fixture(scope="module")
def scene(read: tuple[Scene, Move, ToolLine]) -> Scene:
    """The scene, its goal the move's (what the move alone plans to)."""
    scene, move, _ = read
    return dataclasses.replace(scene, goal=move.goal)


def test_the_line_after_a_move_is_the_next_segment_but_waits(read: tuple[Scene, Move, ToolLine]) -> None:
    _, move, line = read
    wait = Wait(0.2)
    assert line_after([move, line], 0) == 1
    assert line_after([move, wait, wait, line], 0) == 3
    assert line_after([move, Detach(), line], 0) is None  # what it carries changes
    assert line_after([move, move, line], 0) is None
    assert line_after([move], 0) is None and line_after([line, line], 1) is None


def test_a_move_before_a_line_takes_a_goal_from_which_the_line_walks(
    read: tuple[Scene, Move, ToolLine], scene: Scene, panda: ck.Robot
) -> None:
    start_scene, move, line = read
    # the oracle: the goal the move alone takes, and the line's joint path from there, breaks
    alone = build_problem(scene, panda)
    with pytest.raises(ToolLineBrokenError, match=r"singularity|limit|cannot take"):
        line_path(panda, alone.motion.q_goal, line)
    walks = LineWalks(alone.world, line, Requirements.of(alone))
    assert not walks(alone.motion.q_goal)
    # in the task, the move takes another solution of the same pose, and the line walks from it
    task = plan_task(start_scene, [move, line], panda)
    assert task.segments[1].line is not None
    q_goal = task.trajectory(task.segments[1].t0)
    assert walks(q_goal) and not np.allclose(q_goal, alone.motion.q_goal, atol=1e-3)
    pose = ck.frame_poses(panda, q_goal, panda.tcp_frame)
    np.testing.assert_allclose(pose[:3, 3], GOAL_XYZ, atol=1e-3)  # the same goal pose


def test_where_the_soonest_goals_line_walks_the_goal_is_the_moves_own(
    read: tuple[Scene, Move, ToolLine], scene: Scene, panda: ck.Robot
) -> None:
    start_scene, move, _ = read
    down = ToolLine(by=(0.0, 0.0, -0.03), offset_frame="base")  # a short line: it walks from the soonest
    alone = build_problem(scene, panda)
    assert LineWalks(alone.world, down, Requirements.of(alone))(alone.motion.q_goal)
    task = plan_task(start_scene, [move, down], panda)
    np.testing.assert_allclose(task.trajectory(task.segments[1].t0), alone.motion.q_goal, rtol=0.0, atol=1e-9)


def test_a_line_that_breaks_from_every_goal_still_names_where_it_breaks(
    read: tuple[Scene, Move, ToolLine], panda: ck.Robot
) -> None:
    start_scene, move, line = read
    far = dataclasses.replace(line, by=(0.0, 0.0, -2.0))  # two metres down: out of reach
    with pytest.raises(TaskSegmentError, match=r"task\[1\] \(line\): the tool line breaks after") as raised:
        plan_task(start_scene, [move, far], panda)
    assert re.search(
        r"it breaks from each of the \d+ IK solutions of the move's goal tried$", str(raised.value)
    )
    # a line after a joint goal: no goal to choose, nothing said of one
    with pytest.raises(TaskSegmentError) as raised:
        plan_task(start_scene, [Move(start_scene.start), far], panda)
    assert "IK solutions" not in str(raised.value)
