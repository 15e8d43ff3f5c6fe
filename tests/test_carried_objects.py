"""What a trajectory carries, object by object, and where each is at each instant (for the viewer)."""

from __future__ import annotations

import numpy as np

import cpr_kin as ck
from planning.task import task_record
from planning.viz.artifacts import task_carried
from planning.viz.carried_objects import CarriedSpan, carried_poses, carried_spans, recorded_scenes

from .conftest import LIFT, PlannedTask, spline_path

BOX = ck.Obstacle.box((0.04, 0.04, 0.04), (0.0, 0.0, 0.03), rpy=(0.0, 0.2, 0.0), name="part")


def part(name: str = "part", shape: ck.Obstacle | None = BOX) -> ck.Payload:
    return ck.Payload(mass_kg=1.0, shape=shape, name=name)


def test_each_object_is_carried_from_its_attach_to_its_release() -> None:
    held, other, shapeless = part("held"), part("other"), part("mass only", None)
    spans = carried_spans(held, [(1.0, None), (2.0, other), (2.5, shapeless), (3.0, None)], 4.0)
    assert [(s.name, s.attached_s, s.released_s) for s in spans] == [("held", 0.0, 1.0), ("other", 2.0, 2.5)]
    assert spans[0].shape == BOX and spans[0].frame is None
    (kept,) = carried_spans(None, [(1.5, held)], 4.0)  # never released: to the end
    assert (kept.attached_s, kept.released_s) == (1.5, 4.0)
    assert carried_spans(None, [], 4.0) == ()


def test_it_moves_with_its_frame_while_carried_and_rests_before_and_after(robot: ck.Robot) -> None:
    start, goal = ck.tcp_ik(robot, (0.5, 0.45, 0.25)), ck.tcp_ik(robot, (-0.5, 0.45, 0.25))
    trajectory = spline_path(np.stack([start, start + LIFT, goal + LIFT, goal]))  # 3 s
    span = CarriedSpan("part", None, BOX, 1.0, 2.0)
    times = np.linspace(0.0, 3.0, 31)
    poses = carried_poses(robot, trajectory, span, times)
    # the oracle: the tool frame's pose (forward kinematics) times the shape's placement in it
    placed = BOX.placement.homogeneous
    for t, pose in zip(times, poses, strict=True):
        held_at = min(max(t, 1.0), 2.0)
        np.testing.assert_allclose(pose, ck.frame_poses(robot, trajectory(held_at)) @ placed, atol=1e-12)
    assert not np.allclose(poses[10], poses[20])  # it moved while carried
    np.testing.assert_array_equal(poses[0], poses[10])  # resting where it is taken
    np.testing.assert_array_equal(poses[20], poses[30])  # and where it is left


def test_a_planned_tasks_record_gives_its_own_attaches_and_releases(pick_and_place: PlannedTask) -> None:
    read, task = pick_and_place.read, pick_and_place.task
    record = task_record(task)
    robot, trajectory = task.world.robot, task.trajectory
    scenes = recorded_scenes(read.scene, robot, trajectory, read.task, record)
    changes = [(t, after.payload) for t, after in scenes]
    attach = next(s for s in task.segments if s.kind == "attach")
    detach = next(s for s in task.segments if s.kind == "detach")
    assert [(t, p.name if p else None) for t, p in changes] == [(attach.t0, "part"), (detach.t0, None)]
    (span,) = task_carried(task)
    assert (span.name, span.attached_s, span.released_s) == ("part", attach.t0, detach.t0)
    (again,) = carried_spans(read.scene.payload, changes, task.trajectory.duration)
    assert (again.name, again.frame, again.attached_s, again.released_s) == (
        span.name,
        None,
        attach.t0,
        detach.t0,
    )
    # the part taken from the world: placed in the tool as the record's configuration at the attach holds it
    np.testing.assert_allclose(
        again.shape.placement.homogeneous, span.shape.placement.homogeneous, atol=1e-12
    )
    assert [o.name for o in scenes[0][1].obstacles] == ["crate", "lamp", "pipe"]  # the part taken
    assert [o.name for o in scenes[1][1].obstacles][-1] == "part"  # and left, an obstacle again
    assert recorded_scenes(read.scene, robot, trajectory, read.task[:-1], record) == []  # another task's
    swapped = [{**entry, "kind": "free"} if entry["kind"] == "attach" else entry for entry in record]
    assert recorded_scenes(read.scene, robot, trajectory, read.task, swapped) == []
