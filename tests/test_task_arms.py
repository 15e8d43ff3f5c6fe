"""Pick-and-place tasks from scene files on arms no issue names here (a Panda, a UR5), checked independently.

Every millisecond of the planned trajectory, without the planner's code: the tool on each
line (Pinocchio's forward kinematics), joints within range and limits (finite differences of
the samples are left to the planner's exact extrema; the samples themselves are checked),
the torques within the URDF's effort limits with the part's mass where it is carried
(Pinocchio's RNEA on a model with the part appended as a body); and every millisecond
the clearance of the URDF's exact link meshes and of the carried part from the obstacles
(coal on Pinocchio's own collision model: the planner checks convex hulls that contain them).
"""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import package_roots
from planning.errors import TaskSegmentError
from planning.io.robot_entry import robot_spec_of
from planning.io.scene_file import SceneFile, parse_scene_file
from planning.io.shape_entry import obstacle_to_dict
from planning.task import TaskMotion, check_task, plan_task, task_record

DOWN = [3.14159265, 0.0, 0.0]
TASK: list[dict[str, Any]] = [
    {"move": {"pose": {"xyz": [0.5, -0.25, 0.3], "rpy": DOWN}}},
    {"line": {"by": [0.0, 0.0, 0.12]}},  # along the tool's axis: down
    {"wait": 0.2},
    {
        "attach": {
            "name": "can",
            "mass_kg": 2.0,
            "com_in_tcp": [0.0, 0.0, 0.04],
            "shape": {"shape": "cylinder", "radius": 0.03, "length": 0.1, "xyz": [0.0, 0.0, 0.06]},
        }
    },
    {"line": {"by": [0.0, 0.0, -0.12]}},
    {"move": {"pose": {"xyz": [0.45, 0.3, 0.3], "rpy": DOWN}}},
    {"line": {"by": [0.0, 0.0, -0.1], "frame": "base"}},
    {"detach": {"name": "can"}},
    {"line": {"by": [0.0, 0.0, 0.1], "frame": "base"}},
]
ARMS: dict[str, dict[str, Any]] = {
    "panda": {
        "start": [0.0, -0.6, 0.0, -2.2, 0.0, 1.6, 0.8],
        "touch_links": ["panda_hand", "panda_leftfinger", "panda_rightfinger"],
        "mass_kg": 2.0,
    },
    "ur5": {"start": [-1.0, -1.57, 1.57, -1.57, -1.57, 0.0], "touch_links": ["wrist_3_link"], "mass_kg": 3.0},
}
POST = {"name": "post", "shape": "box", "size": [0.08, 0.08, 0.5], "xyz": [0.55, 0.03, 0.25]}


def scene_file(arm: str) -> SceneFile:
    task = copy.deepcopy(TASK)
    task[3]["attach"] |= {"touch_links": ARMS[arm]["touch_links"], "mass_kg": ARMS[arm]["mass_kg"]}
    document = {
        "name": f"{arm}_pick_and_place",
        "robot": arm,
        "safety_margin": 0.02,
        "start": {"q": ARMS[arm]["start"]},
        "task": task,
        "obstacles": [POST],
    }
    return parse_scene_file(document, f"{arm} task")


@pytest.fixture(scope="module", params=sorted(ARMS))
def planned(request: pytest.FixtureRequest) -> tuple[SceneFile, TaskMotion]:
    read = scene_file(request.param)
    return read, plan_task(read.scene, read.task)


def test_the_task_plans_and_passes_its_own_check(planned: tuple[SceneFile, TaskMotion]) -> None:
    read, task = planned
    assert task.accepted, task.problems
    kinds = ["free", "line", "wait", "attach", "line", "free", "line", "detach", "line"]
    assert [s.kind for s in task.segments] == kinds
    checked = check_task(read.scene, read.task, task.trajectory, task_record(task))
    assert checked.accepted, checked.problems


def test_every_millisecond_the_tool_keeps_its_lines_and_the_joints_their_ranges(
    planned: tuple[SceneFile, TaskMotion],
) -> None:
    _, task = planned
    robot = task.world.robot
    model = robot.model
    data, fid = model.createData(), model.getFrameId(robot.tcp_frame)
    trajectory = task.trajectory
    for segment in (s for s in task.segments if s.line is not None):
        assert segment.line is not None
        start, goal = segment.line.start.placement(), segment.line.goal.placement()
        shift = goal.translation - start.translation
        assert 0.05 <= np.linalg.norm(shift) <= 0.2
        for q in trajectory(np.arange(segment.t0, segment.t1, 1e-3)):
            pin.framesForwardKinematics(model, data, q)
            pose = data.oMf[fid]
            sigma = np.clip((pose.translation - start.translation) @ shift / (shift @ shift), 0.0, 1.0)
            assert np.linalg.norm(pose.translation - start.translation - sigma * shift) <= 1e-3
            assert np.linalg.norm(pin.log3(start.rotation.T @ pose.rotation)) <= 0.01  # a line keeps it
    q = trajectory(np.arange(0.0, trajectory.duration, 1e-3))
    assert np.all(q >= model.lowerPositionLimit - 1e-9) and np.all(q <= model.upperPositionLimit + 1e-9)


def test_every_millisecond_the_torques_are_within_the_effort_limits_with_the_part(
    planned: tuple[SceneFile, TaskMotion],
) -> None:
    read, task = planned
    robot, trajectory = task.world.robot, task.trajectory
    attach, detach = task.segments[3], task.segments[7]
    part = read.task[3].payload  # type: ignore[union-attr]
    carrying = robot.model.copy()
    frame = carrying.frames[carrying.getFrameId(robot.tcp_frame)]
    body = pin.Inertia.FromSphere(part.mass_kg, 1e-3)  # a point mass, as the payload without inertia
    carrying.appendBodyToJoint(
        frame.parentJoint, body, frame.placement * pin.SE3(np.eye(3), np.array([0, 0, 0.04]))
    )
    for model, (t0, t1) in (
        (robot.model, (0.0, attach.t0)),
        (carrying, (attach.t0, detach.t0)),
        (robot.model, (detach.t0, trajectory.duration)),
    ):
        data = model.createData()
        times = np.arange(t0, t1, 1e-3)
        q, v, a = trajectory(times), trajectory(times, 1), trajectory(times, 2)
        tau = np.array([pin.rnea(model, data, *state) for state in zip(q, v, a, strict=True)])
        assert np.all(np.abs(tau) <= model.effortLimit * (1 + 1e-6))


def test_the_exact_link_meshes_and_the_part_keep_the_margin(planned: tuple[SceneFile, TaskMotion]) -> None:
    read, task = planned
    robot, trajectory = task.world.robot, task.trajectory
    urdf = Path(robot.urdf_path)
    geometry = pin.buildGeomFromUrdf(
        robot.model, str(urdf), pin.COLLISION, package_dirs=[str(p) for p in package_roots(urdf)]
    )
    data, geometry_data = robot.model.createData(), geometry.createData()
    post = coal.Box(*POST["size"])
    post_in_world = coal.Transform3s(np.eye(3), np.array(POST["xyz"]))
    can = coal.Cylinder(0.03, 0.1)
    attach, detach = task.segments[3], task.segments[7]
    fid = robot.model.getFrameId(robot.tcp_frame)
    least = np.inf
    for t in np.arange(0.0, trajectory.duration, 1e-3):
        q = trajectory(t)
        pin.framesForwardKinematics(robot.model, data, q)
        pin.updateGeometryPlacements(robot.model, data, geometry, geometry_data)
        shapes = [(g.geometry, geometry_data.oMg[k]) for k, g in enumerate(geometry.geometryObjects)]
        if attach.t0 <= t <= detach.t0:
            shapes.append((can, data.oMf[fid] * pin.SE3(np.eye(3), np.array([0.0, 0.0, 0.06]))))
        for shape, placement in shapes:
            result = coal.DistanceResult()
            coal.distance(
                shape,
                coal.Transform3s(placement.rotation, placement.translation),
                post,
                post_in_world,
                coal.DistanceRequest(),
                result,
            )
            least = min(least, result.min_distance)
    assert least >= read.scene.safety_margin - 1e-6
    assert least <= task.certified_min_clearance_m + 0.05  # the same motion: near the certified figure


def test_the_can_taken_from_where_it_stands_and_left_is_kept_clear_of_every_other_link(
    planned: tuple[SceneFile, TaskMotion],
) -> None:
    """The same task with the can an obstacle until the attach takes it and again where it is left."""
    read, task = planned
    arm = read.scene.name.removesuffix("_pick_and_place")
    robot, attach = task.world.robot, task.segments[3]
    assert attach.payload is not None
    standing = ck.left_at(robot, attach.payload, task.trajectory(attach.t0))  # where the gripper finds it
    holding = sorted(ck.holding_links(robot, attach.payload))  # the hand's links, as while it carries the can
    can = obstacle_to_dict(standing) | {"name": "can", "touch_links": holding}
    document = copy.deepcopy(TASK)
    document[3]["attach"] = {"name": "can", "mass_kg": ARMS[arm]["mass_kg"], "com_in_tcp": [0.0, 0.0, 0.04]}
    scene = {"robot": arm, "safety_margin": 0.02, "start": {"q": ARMS[arm]["start"]}, "task": document}
    taking = parse_scene_file(scene | {"obstacles": [POST, can]}, f"{arm} task")
    planned_again = plan_task(taking.scene, taking.task)
    assert planned_again.accepted, planned_again.problems
    assert check_task(
        taking.scene, taking.task, planned_again.trajectory, task_record(planned_again)
    ).accepted
    # independently: coal on the URDF's exact meshes of every link but the gripper's, against the can
    # where it stands before the attach and where it is left after the detach
    trajectory, taken, left = planned_again.trajectory, planned_again.segments[3], planned_again.segments[7]
    released = ck.left_at(robot, taken.payload, trajectory(left.t0))  # type: ignore[arg-type]
    urdf = Path(robot.urdf_path)
    geometry = pin.buildGeomFromUrdf(
        robot.model, str(urdf), pin.COLLISION, package_dirs=[str(p) for p in package_roots(urdf)]
    )
    data, geometry_data = robot.model.createData(), geometry.createData()
    others = [
        k
        for k, g in enumerate(geometry.geometryObjects)
        if robot.model.frames[g.parentFrame].name not in holding
    ]
    least = np.inf
    for t in np.arange(0.0, trajectory.duration, 2e-3):
        if taken.t0 <= t <= left.t0:
            continue  # carried: the planner's own check of what it carries (the tests above)
        where = standing if t < taken.t0 else released
        pin.framesForwardKinematics(robot.model, data, trajectory(t))
        pin.updateGeometryPlacements(robot.model, data, geometry, geometry_data)
        at = where.placement
        for k in others:
            placement = geometry_data.oMg[k]
            result = coal.DistanceResult()
            coal.distance(
                geometry.geometryObjects[k].geometry,
                coal.Transform3s(placement.rotation, placement.translation),
                where.geometry(),
                coal.Transform3s(at.rotation, at.translation),
                coal.DistanceRequest(),
                result,
            )
            least = min(least, result.min_distance)
    assert least >= taking.scene.safety_margin - 1e-6


@pytest.mark.parametrize("arm", ["xarm7", "z1", "ur10"])
def test_a_task_about_a_random_start_plans_and_checks_on_arms_no_task_test_was_written_for(arm: str) -> None:
    """A grasp and an upright carry near a seeded start of each arm; the z1's tool lines drive its
    last joint to its limit, where the spline through the line's samples once passed it."""
    robot = robot_spec_of(arm, Path(".")).load()
    rng = np.random.default_rng(0)
    world = ck.CollisionWorld(robot, [])
    middle = 0.5 * (robot.limits.lower + robot.limits.upper)
    for _ in range(200):  # the first seeded draw 2 cm clear of itself, else the last (the z1's
        q = 0.6 * rng.uniform(robot.limits.lower, robot.limits.upper) + 0.4 * middle  # gripper is
        if world.keeps_clearance(q[None], 0.0, 0.02)[0]:  # within 2 cm of its wrist in every draw)
            break
    pose = ck.frame_poses(robot, q)
    quat = pin.Quaternion(pose[:3, :3]).coeffs().tolist()

    def near(offset: list[float]) -> dict[str, Any]:
        return {"pose": {"xyz": (pose[:3, 3] + np.array(offset)).tolist(), "quat_xyzw": quat}}

    document = {
        "robot": arm,
        "safety_margin": 0.01,
        "start": {"q": q.tolist()},
        "task": [
            {"move": near([0.03, -0.06, 0.0])},
            {"line": {"by": [0, 0, 0.05]}},
            {"wait": 0.2},
            {
                "attach": {
                    "name": "part",
                    "mass_kg": 0.3,
                    "shape": {"shape": "sphere", "radius": 0.02, "xyz": [0, 0, 0.03]},
                }
            },
            {"line": {"by": [0, 0, -0.05]}},
            {"move": {**near([0.03, 0.06, 0.02]), "constraint": {"axes": ["x", "y"], "angle_rad": 0.0873}}},
            {"detach": {}},
        ],
    }
    read = parse_scene_file(document, f"{arm} task")
    task = plan_task(read.scene, read.task)
    assert task.accepted, task.problems
    assert check_task(read.scene, read.task, task.trajectory, task_record(task)).accepted
    positions = task.trajectory(np.arange(0.0, task.trajectory.duration, 1e-3))
    assert (positions >= robot.limits.lower - 1e-9).all() and (positions <= robot.limits.upper + 1e-9).all()


@pytest.mark.parametrize("touching", [True, False])
def test_a_can_set_down_on_a_table_touches_it_only_where_the_payload_says_so(
    planned: tuple[SceneFile, TaskMotion], touching: bool
) -> None:
    """The can lowered until it stands on a table (MoveIt's allowed contact of an attached object)."""
    read, task = planned
    arm = read.scene.name.removesuffix("_pick_and_place")
    robot, attach, detach = task.world.robot, task.segments[3], task.segments[7]
    assert attach.payload is not None
    standing = ck.left_at(robot, attach.payload, task.trajectory(detach.t0))  # where it is set down
    axis = standing.placement.rotation[:, 2]
    bottom = standing.xyz[2] - 0.05 * abs(axis[2]) - 0.03 * np.hypot(axis[0], axis[1])  # its lowest point
    table = {"name": "table", "shape": "box", "size": [0.3, 0.3, 0.04]}
    table["xyz"] = [float(standing.xyz[0]), float(standing.xyz[1]), float(bottom - 0.02)]
    document = copy.deepcopy(TASK)
    document[3]["attach"] |= {"touch_links": ARMS[arm]["touch_links"], "mass_kg": ARMS[arm]["mass_kg"]}
    if touching:
        document[3]["attach"]["touch_obstacles"] = ["table"]
    scene = {"robot": arm, "safety_margin": 0.02, "start": {"q": ARMS[arm]["start"]}, "task": document}
    read = parse_scene_file(scene | {"obstacles": [POST, table]}, f"{arm} place")
    if not touching:  # the can would stand inside the table's margin: the line down breaks
        with pytest.raises(TaskSegmentError, match=r"task\[6\] \(line\).*'can' is .* from 'table'"):
            plan_task(read.scene, read.task)
        return
    placed = plan_task(read.scene, read.task)
    assert placed.accepted, placed.problems
    assert check_task(read.scene, read.task, placed.trajectory, task_record(placed)).accepted
    payload = read.task[3].payload  # type: ignore[union-attr]
    end = placed.trajectory(placed.segments[7].t0)  # set down
    allowed = ck.CollisionWorld(ck.carrying(robot, payload), read.scene.obstacles)
    assert allowed.clearance(end).min_clearance_m >= read.scene.safety_margin  # every pair but the can's
    bare = dataclasses.replace(payload, touch_obstacles=())
    every = ck.CollisionWorld(ck.carrying(robot, bare), [table_of(read)])
    assert every.clearance(end).min_clearance_m < 0.005  # the can stands on the table


def table_of(read: SceneFile) -> ck.Obstacle:
    return next(o for o in read.scene.obstacles if o.name == "table")
