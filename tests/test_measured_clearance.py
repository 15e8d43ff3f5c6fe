"""A task's path coloured by what its certified checks measured, each segment in its own world."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.task.task_record import task_record
from planning.viz.carried_objects import recorded_scenes
from planning.viz.measured_clearance import sampled_clearance, task_clearance

from .conftest import PlannedTask


def test_the_measured_clearance_is_each_segments_check_on_the_tasks_clock(
    pick_and_place: PlannedTask,
) -> None:
    task = pick_and_place.task
    measured = task_clearance(task)
    assert np.all(np.diff(measured.times_s) >= 0.0)
    assert measured.times_s[0] == 0.0 and measured.times_s[-1] <= task.trajectory.duration + 1e-12
    for segment in task.segments:
        if segment.verification is None:
            continue
        check = segment.verification.check
        at = segment.t0 + np.asarray(check.times) - check.times[0]  # on the clock of its run of motions
        assert at[-1] == pytest.approx(segment.t1, abs=1e-9)
        inner = (at > segment.t0) & (at < segment.t1)  # a junction's instant is two segments'
        least = np.asarray(check.clearance_m).min(axis=1)
        np.testing.assert_allclose(measured.at(at[inner]), least[inner], rtol=0, atol=1e-12)


def test_after_the_release_it_sees_the_part_the_drawn_world_does_not_hold(
    pick_and_place: PlannedTask,
) -> None:
    task = pick_and_place.task
    detach = next(i for i, s in enumerate(task.segments) if s.kind == "detach")
    rise = task.segments[detach + 1]
    assert rise.verification is not None
    check = rise.verification.check
    assert check.worst_pair is not None and check.worst_pair[1] == "part"
    worst = rise.t0 + check.worst_time - check.times[0]
    q = task.trajectory(np.array([worst]))
    drawn_world = task.world.clearance_batch(q).min_clearance_m[0]  # no part there: it is drawn as carried
    assert task_clearance(task).at(np.array([worst]))[0] == pytest.approx(check.sampled_min_m, abs=1e-12)
    assert check.sampled_min_m < drawn_world
    left = ck.CollisionWorld(task.world.robot, [*task.world.obstacles, _left_part(task, detach)])
    assert left.clearance(q[0]).min_clearance_m == pytest.approx(check.sampled_min_m, abs=1e-6)  # the oracle


def _left_part(task: object, detach: int) -> ck.Obstacle:
    from planning.task.task_plan import TaskMotion

    assert isinstance(task, TaskMotion)
    released = task.segments[detach].payload
    assert released is not None
    return ck.left_at(task.world.robot, released, task.trajectory(task.segments[detach].t0))


def test_a_task_read_back_is_sampled_each_instant_in_its_own_world(pick_and_place: PlannedTask) -> None:
    """What `cpr-plan show` colours a task's file by: no checks to read, so its path sampled in the
    world of each instant (the part waiting, then carried, then left), against the plan's checks."""
    read, task = pick_and_place.read, pick_and_place.task
    start = (float(task.trajectory.knots[0]), read.scene)
    scenes = recorded_scenes(read.scene, task.world.robot, task.trajectory, read.task, task_record(task))
    sampled = sampled_clearance(task.world.robot, task.trajectory, [start, *scenes], samples=800)
    checked = task_clearance(task)
    assert sampled.clearance_m.min() >= task.certified_min_clearance_m - 1e-9  # the bound is below
    assert sampled.clearance_m.min() == pytest.approx(checked.clearance_m.min(), abs=2e-3)  # 5 ms apart
    assert sampled.closest is not None
    assert sampled.closest.obstacle in {o.name for o in read.scene.obstacles} | {"part"}
    # one query of the instant, another of the batch: the same pair within coal's GJK tolerance
    assert sampled.closest.distance_m == pytest.approx(sampled.clearance_m.min(), abs=1e-6)
    alone = sampled_clearance(task.world.robot, task.trajectory, [start], samples=800)  # one world
    assert alone.clearance_m.min() < sampled.clearance_m.min() - 1e-3  # the part would be in the way
