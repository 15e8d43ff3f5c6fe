"""Objects change hands with the world: an attach takes an obstacle, a detach leaves the object in it."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import trimesh

import cpr_kin as ck
from planning.errors import PlanningError
from planning.pipeline.scene import Scene
from planning.pipeline.target import Target
from planning.task import Attach, Detach
from planning.task.holding import changed_object, scene_after, untaken
from planning.viz.artifacts import task_carried
from planning.viz.carried_objects import carried_poses

from .conftest import PlannedTask

Q = np.array([0.3, 0.4, 0.3, 0.2, -0.1])
BOX = ck.Obstacle.box((0.04, 0.04, 0.06), (0.0, 0.01, 0.03), (0.1, 0.0, 0.4), name="part")


@pytest.fixture(scope="module")
def base() -> ck.Robot:
    return ck.load_cpr()


def _scene(obstacles: tuple[ck.Obstacle, ...] = (), payload: ck.Payload | None = None) -> Scene:
    return Scene(start=Target(q=tuple(Q)), goal=Target(q=tuple(Q)), obstacles=obstacles, payload=payload)


def _placed_by_pinocchio(robot: ck.Robot, name: str, q: np.ndarray) -> np.ndarray:
    """The carried shape's pose in the world, from Pinocchio's geometry placement (not frame_poses)."""
    data, geometry_data = robot.model.createData(), robot.collision_model.createData()
    pin.updateGeometryPlacements(robot.model, data, robot.collision_model, geometry_data, q)
    return np.asarray(geometry_data.oMg[robot.collision_model.getGeometryId(name)].homogeneous)


def test_a_detach_leaves_the_object_where_its_frame_holds_it_for_the_hand_to_touch(base: ck.Robot) -> None:
    held = ck.Payload(0.5, shape=BOX, touch_links=("arm_link",), name="part")
    after = scene_after(_scene(payload=held), base, Q, Detach("part"))
    (left,) = after.obstacles
    assert after.payload is None and left.name == "part" and left.shape == "box"
    np.testing.assert_allclose(
        left.placement.homogeneous, _placed_by_pinocchio(ck.carrying(base, held), "part", Q), atol=1e-12
    )
    assert set(left.touch_links) == {"tool_link", "wrist_link", "arm_link"} == ck.holding_links(base, held)
    mass_only = scene_after(_scene(payload=ck.Payload(0.5, name="load")), base, Q, Detach())
    assert mass_only.obstacles == () and mass_only.payload is None


def test_a_mesh_is_left_as_it_was_carried_its_convex_hull(base: ck.Robot, tmp_path: Path) -> None:
    trimesh.creation.box(extents=(0.04, 0.04, 0.04)).export(tmp_path / "part.stl")
    surface = ck.Obstacle.from_mesh(tmp_path / "part.stl", (0, 0, 0.03), convex=False, name="part")
    left = ck.left_at(base, ck.Payload(0.5, shape=surface, name="part"), Q)
    assert left.shape == "mesh" and left.convex and left.mesh == surface.mesh


def test_an_attach_takes_the_obstacle_where_it_is_and_a_detach_gives_it_back(base: ck.Robot) -> None:
    placed = dataclasses.replace(BOX, xyz=ck.frame_positions(base, Q) + 0.02, touch_links=("tool_link",))
    other = ck.Obstacle.sphere(0.1, (1.0, 1.0, 1.0), name="ball")
    taken = scene_after(_scene((other, placed)), base, Q, Attach(ck.Payload(1.5, name="part")))
    assert taken.obstacles == (other,)
    assert (
        taken.payload is not None
        and taken.payload.mass_kg == 1.5
        and taken.payload.touch_links == ("tool_link",)
    )
    carried = ck.carrying(base, taken.payload)
    np.testing.assert_allclose(
        _placed_by_pinocchio(carried, "part", Q), placed.placement.homogeneous, atol=1e-12
    )
    back = scene_after(taken, base, Q, Detach())
    assert back.payload is None and back.obstacles[0] == other
    np.testing.assert_allclose(
        back.obstacles[1].placement.homogeneous, placed.placement.homogeneous, atol=1e-12
    )


def test_what_cannot_change_hands_is_refused_naming_it(base: ck.Robot) -> None:
    shaped = ck.Payload(1.0, shape=BOX, name="part")
    with pytest.raises(PlanningError, match=r"attach: .*obstacle 'part' another.*leave out its shape"):
        scene_after(_scene((BOX,)), base, Q, Attach(shaped))
    cloud = ck.Obstacle(
        shape="voxels", xyz=np.zeros(3), points=np.zeros((1, 3)), resolution=0.02, name="cloud"
    )
    with pytest.raises(PlanningError, match="attach: obstacle 'cloud' is a point cloud"):
        scene_after(_scene((cloud,)), base, Q, Attach(ck.Payload(1.0, name="cloud")))
    with pytest.raises(PlanningError, match="detach: 'part' would be left in the world beside an obstacle"):
        scene_after(_scene((BOX,), shaped), base, Q, Detach())
    with pytest.raises(PlanningError, match="detach: the robot carries nothing"):
        scene_after(_scene(), base, Q, Detach())
    with pytest.raises(PlanningError, match="attach: the robot already carries 'part'"):
        scene_after(_scene(payload=shaped), base, Q, Attach(ck.Payload(1.0, name="other")))
    # a name no obstacle has, no shape, no mass: a misspelt obstacle, which used to carry nothing
    with pytest.raises(
        PlanningError, match=r"attach: 'prat' is no obstacle .* it would carry nothing; .*\['part'\]"
    ):
        scene_after(_scene((BOX,)), base, Q, Attach(ck.Payload(0.0, name="prat")))
    assert scene_after(_scene((BOX,)), base, Q, Attach(ck.Payload(0.2, name="load"))).payload is not None


def test_the_example_checks_the_part_where_it_waits_and_where_it_is_left(pick_and_place: PlannedTask) -> None:
    read, task = pick_and_place.read, pick_and_place.task
    waiting = next(o for o in read.scene.obstacles if o.name == "part")
    assert "part" not in {o.name for o in task.world.obstacles}  # drawn as what the robot carries
    assert untaken(read.scene.obstacles, [None]) == list(read.scene.obstacles)
    (span,) = task_carried(task)
    np.testing.assert_allclose(  # drawn resting where it waits, before the attach
        carried_poses(task.world.robot, task.trajectory, span, np.array([0.0]))[0],
        waiting.placement.homogeneous,
        atol=1e-9,
    )
    detach = next(i for i, s in enumerate(task.segments) if s.kind == "detach")
    rise = task.segments[detach + 1]
    assert rise.verification is not None
    check = rise.verification.check
    assert check.worst_pair is not None and check.worst_pair[1] == "part"  # the part it left is checked
    released = task.segments[detach].payload
    assert released is not None
    left = ck.left_at(task.world.robot, released, task.trajectory(rise.t0))
    oracle = ck.CollisionWorld(task.world.robot, [left]).clearance(
        task.trajectory(rise.t0 + check.worst_time - check.times[0])
    )
    assert check.certified_min_m <= oracle.min_clearance_m + 1e-9
    assert check.sampled_min_m == pytest.approx(oracle.min_clearance_m, abs=1e-6)


def test_an_attach_touching_no_object_of_the_task_is_refused_before_anything_is_planned(
    pick_and_place: PlannedTask, monkeypatch: pytest.MonkeyPatch
) -> None:
    import planning.task.task_plan as task_plan

    def nothing_planned(*args: object, **kwargs: object) -> None:
        raise AssertionError("a segment was planned before the task's names were checked")

    monkeypatch.setattr(task_plan, "build_problem", nothing_planned)
    read = pick_and_place.read
    segments = list(read.task)
    attach = next(i for i, s in enumerate(segments) if isinstance(s, Attach))
    payload = segments[attach].payload  # type: ignore[union-attr]
    segments[attach] = Attach(dataclasses.replace(payload, touch_obstacles=("crate", "tabel")))
    with pytest.raises(PlanningError, match=r"task\[3\] \(attach\): touch_obstacles \['tabel'\] are"):
        task_plan.plan_task(read.scene, segments)


def test_the_object_a_change_concerns_is_the_one_taken_or_the_one_let_go(base: ck.Robot) -> None:
    placed = dataclasses.replace(BOX, xyz=ck.frame_positions(base, Q) + 0.02)
    before = _scene((placed,))
    attach = Attach(ck.Payload(1.5, name="part"))
    taken = scene_after(before, base, Q, attach)
    assert changed_object(attach, before, taken) is taken.payload is not None  # with the obstacle's shape
    assert taken.payload.shape is not None
    released = scene_after(taken, base, Q, Detach())
    assert changed_object(Detach(), taken, released) is taken.payload and released.payload is None
