"""An upright carry: a free motion that keeps the tool's z axis within 5 degrees, on a UR5 and a Panda.

Checked every
millisecond without the planner's code: the angle between the tool's z axis and the
reference's (Pinocchio's forward kinematics, ``arccos``), the record's constraint, and the
record kept and checked.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.kinematics.ik_target import IkTarget
from cpr_kin.kinematics.numerical_ik import solve_ik
from cpr_kin.model.packages import example_robot
from planning.errors import NoSolutionError, PlanningError
from planning.io.scene_file import SceneFile, parse_scene_file
from planning.pipeline.verification import Requirements, verify_trajectory
from planning.task import Move, TaskMotion, check_task, plan_task, record_problems, task_record
from planning.task.free_motion import free_problem
from planning.task.held_orientation import HeldMotion, _held, _held_sparsest, goal_on_constraint
from planning.task.orientation import OrientationConstraint
from planning.task.orientation_projection import Projector
from planning.task.orientation_rrt import STEP_M, orientation_path

UPRIGHT = {"axes": ["x", "y"], "angle_rad": 0.0873}
DOWN = [3.14159265, 0.0, 0.0]
ARMS: dict[str, dict[str, Any]] = {
    "panda": {"start": [0.0, -0.6, 0.0, -2.2, 0.0, 1.6, 0.8]},
    "ur5": {"start": [-1.0, -1.57, 1.57, -1.57, -1.57, 0.0]},
}


def scene_file(arm: str, constraint: dict[str, Any] = UPRIGHT) -> SceneFile:
    document = {
        "robot": arm,
        "safety_margin": 0.02,
        "start": {"q": ARMS[arm]["start"]},
        "task": [
            {"move": {"pose": {"xyz": [0.5, -0.25, 0.3], "rpy": DOWN}}},
            {
                "attach": {
                    "name": "glass",
                    "mass_kg": 0.5,
                    "shape": {"shape": "cylinder", "radius": 0.03, "length": 0.1, "xyz": [0, 0, 0.06]},
                }
            },
            {"move": {"pose": {"xyz": [0.45, 0.3, 0.3], "rpy": DOWN}, "constraint": constraint}},
            {"detach": {}},
        ],
        "obstacles": [{"name": "post", "shape": "box", "size": [0.08, 0.08, 0.5], "xyz": [0.55, 0.03, 0.25]}],
    }
    return parse_scene_file(document, f"{arm} upright carry")


@pytest.fixture(scope="module", params=sorted(ARMS))
def carried(request: pytest.FixtureRequest) -> tuple[str, SceneFile, TaskMotion]:
    read = scene_file(request.param)
    return request.param, read, plan_task(read.scene, read.task)


def test_the_glass_stays_upright_every_millisecond(carried: tuple[str, SceneFile, TaskMotion]) -> None:
    _, _, task = carried
    assert task.accepted, task.problems
    carry = task.segments[2]
    assert carry.held is not None
    robot = task.world.robot
    model, data = robot.model, robot.model.createData()
    fid = model.getFrameId(robot.tcp_frame)
    pin.framesForwardKinematics(model, data, task.trajectory(carry.t0))
    upright = data.oMf[fid].rotation[:, 2].copy()  # the tool's z axis where the carry starts
    tilts = []
    for q in task.trajectory(np.arange(carry.t0, carry.t1, 1e-3)):
        pin.framesForwardKinematics(model, data, q)
        tilts.append(np.arccos(np.clip(data.oMf[fid].rotation[:, 2] @ upright, -1.0, 1.0)))
    assert max(tilts) <= 0.0873
    assert max(tilts) <= carry.held.deviation.angle_rad + 1e-9  # the certified bound bounds them
    free = task.segments[0]  # the motion to the glass has no constraint: it tilts the tool freely
    assert free.held is None


def test_the_record_holds_the_constraint_and_a_tighter_one_is_caught(
    carried: tuple[str, SceneFile, TaskMotion],
) -> None:
    _, read, task = carried
    record = task_record(task)
    constraint = record[2]["constraint"]
    assert constraint["axes"] == ["x", "y"] and constraint["angle_rad"] == 0.0873
    assert constraint["frame"] == task.world.robot.tcp_frame and len(constraint["quat_xyzw"]) == 4
    assert check_task(read.scene, read.task, task.trajectory, record).accepted
    tighter = copy.deepcopy(record)
    tighter[2]["constraint"]["angle_rad"] = 1e-4
    found = record_problems(task.world.robot, task.trajectory, tighter)
    assert any(p.startswith("task entry 2 (free) turns") for p in found)
    checked = check_task(read.scene, read.task, task.trajectory, tighter).problems
    assert any(p.startswith("task[2] (free) records constraint") for p in checked)
    unconstrained = list(read.task)
    move = unconstrained[2]
    assert isinstance(move, Move)
    unconstrained[2] = Move(move.goal)
    found = check_task(read.scene, unconstrained, task.trajectory, record).problems
    assert found == ("task[2] (free) records a constraint; the task's motion has none",)


def test_a_constraint_the_start_breaks_is_refused_naming_the_segment() -> None:
    up = {**UPRIGHT, "rpy": [0.0, 0.0, 0.0]}  # the tool's z axis up, where it points down
    read = scene_file("ur5", up)
    with pytest.raises(PlanningError, match=r"task\[2\] \(move\): the motion's start holds 'tool0' 3\.14"):
        plan_task(read.scene, read.task)


def around_the_post() -> tuple[ck.CollisionWorld, Projector, Requirements, np.ndarray]:
    """A Panda's upright carry round a post, the straight way blocked: the path RRT-Connect plans on it."""
    robot = ck.load_robot(example_robot("panda"))
    post = ck.Obstacle.box((0.08, 0.08, 0.5), (0.55, 0.03, 0.25), name="post")
    world = ck.CollisionWorld(robot, [post])
    down = pin.rpy.rpyToMatrix(3.14159265, 0.0, 0.0)
    ends = []
    for xyz in ((0.5, -0.25, 0.3), (0.45, 0.3, 0.3)):
        target = IkTarget(position=np.array(xyz), rotation=np.asarray(down))
        ends.append(solve_ik(robot, target, seed_q=[0.0, -0.6, 0.0, -2.2, 0.0, 1.6, 0.8]))
    constraint = OrientationConstraint(("x", "y"), 0.0873)
    reference = ck.frame_poses(robot, ends[0])[:3, :3]
    projector = Projector(robot, robot.tcp_frame, constraint, reference)
    required = Requirements(margin_m=0.02, step_m=0.005)
    straight = ends[0] + np.linspace(0.0, 1.0, 50)[:, None] * (ends[1] - ends[0])
    assert not world.keeps_clearance(straight, 0.02, 0.01).all()  # the straight way hits the post
    path = orientation_path(world, projector, ends[0], ends[1], required, np.random.default_rng(0))
    np.testing.assert_allclose(path[[0, -1]], ends, atol=1e-12)
    return world, projector, required, path


def test_rrt_on_the_constraint_finds_an_upright_way_around_a_post_where_the_straight_one_is_blocked() -> None:
    world, projector, _, path = around_the_post()
    assert projector.angles(path).max() <= projector.aim_rad + 1e-9
    assert world.keeps_clearance(path, 0.02 + STEP_M, 0.01).all()
    radii = ck.motion_radii(world.robot)
    assert (np.abs(np.diff(path, axis=0)) @ radii).max() <= 2 * STEP_M + 1e-9


def test_a_path_planned_on_the_constraint_is_timed_through_its_steps_sparsely() -> None:
    """Each step is projected on its own: a spline through all of them zigzags and must crawl."""
    world, projector, required, path = around_the_post()
    motion = _held_sparsest(world, projector, path, required, bent=False)
    every = _held(world, projector, path, required, bent=False)
    assert len(motion.samples) < len(path) // 2
    assert verify_trajectory(world, motion.trajectory, required).accepted
    assert motion.deviation.angle_rad <= projector.constraint.angle_rad
    assert motion.trajectory.duration < 0.8 * every.trajectory.duration


def test_a_bent_free_path_is_timed_through_its_samples_sparsely(monkeypatch: pytest.MonkeyPatch) -> None:
    """The free path's samples, each bent onto the constraint on its own, zigzag as the RRT's steps do."""
    import planning.task.held_orientation as held

    sparsest, calls = held._held_sparsest, []

    def recorded(*args: Any, **kwargs: Any) -> HeldMotion:
        motion = sparsest(*args, **kwargs)
        calls.append((args, kwargs, motion))
        return motion

    monkeypatch.setattr(held, "_held_sparsest", recorded)
    read = scene_file("ur5")  # its free path bends onto the constraint clear of the post
    plan_task(read.scene, read.task)
    (world, projector, samples, required), kwargs, motion = calls[0]
    assert kwargs["bent"] and motion.bent
    assert len(motion.samples) < len(samples) // 2
    assert verify_trajectory(world, motion.trajectory, required).accepted
    try:  # through every sample: much longer, or (as here) a corner it could pass only at rest
        every = _held(world, projector, samples, required, bent=True)
    except NoSolutionError as crawl:
        assert "only at rest" in str(crawl)
    else:
        assert motion.trajectory.duration < 0.8 * every.trajectory.duration


def test_a_bent_path_that_cannot_be_timed_gives_way_to_one_planned_on_the_constraint(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """As a UR5's bent path did on one machine: a corner it can pass only at rest (MemoryError before)."""
    import planning.task.held_orientation as held

    timed, calls = held._timed, []

    bent_tries = len(held.SPARSER) + 1  # the sparser splines through the bent samples, then all of them

    def bent_fails(projector: Projector, path: Any, required: Requirements) -> Any:
        calls.append(path)
        if len(calls) <= bent_tries:
            raise NoSolutionError("the path cannot be timed: at the limits it takes 6.5e+09 s")
        return timed(projector, path, required)

    monkeypatch.setattr(held, "_timed", bent_fails)
    read = scene_file("ur5")  # its free path bends onto the constraint clear of the post
    task = plan_task(read.scene, read.task)
    carry = task.segments[2].held
    assert task.accepted and carry is not None and not carry.bent and len(calls) > bent_tries
    assert check_task(read.scene, read.task, task.trajectory, task_record(task)).accepted


UR10_START = [5.608, -1.324, 1.832, -2.079, -1.57, 4.038]  # tool down, the base 0.68 rad from its limit
UR10_GOAL = IkTarget(position=np.array([0.65, 0.4, 0.35]), rotation=pin.rpy.rpyToMatrix(*DOWN))


def test_a_goal_is_on_the_constraint_where_the_straight_path_to_it_bends_onto_it() -> None:
    # the UR10's nearest solution of a pose round the other side leaves the start's branch (the
    # elbow flipped, or, since its starts are drawn within the turn about the seed, the wrist):
    # bending the straight path to it leaves the constraint; a solution on the start's branch
    # (elbow and wrist as they are) bends without a jump
    ur10 = ck.load_robot(example_robot("ur10"))
    start = np.array(UR10_START)
    reached = goal_on_constraint(ur10, OrientationConstraint(("x", "y"), 0.0873), start)
    nearest = solve_ik(ur10, UR10_GOAL, start)
    assert start[2] > 0 > start[4] and not reached(nearest)
    assert nearest[2] < 0 or nearest[4] > 0  # the elbow or the wrist flipped
    on_branch = solve_ik(ur10, UR10_GOAL, start, accept=reached)
    assert reached(on_branch) and on_branch[2] > 0 and on_branch[4] < 0
    assert reached(start)  # a goal where it starts


def test_the_goal_is_tested_from_the_start_the_plan_takes() -> None:
    # a start given as a pose is solved by the planner (the nearest IK solution clear of the
    # margins); the goal's test is built from that configuration, the one the carry leaves from
    ur10 = ck.load_robot(example_robot("ur10"))
    tcp_in_base = ck.frame_poses(ur10, np.array([UR10_START]), ur10.tcp_frame)[0]
    rpy = pin.rpy.matrixToRpy(tcp_in_base[:3, :3]).tolist()
    start = {"pose": {"xyz": tcp_in_base[:3, 3].tolist(), "rpy": rpy}}
    goal = {"pose": {"xyz": [0.65, 0.4, 0.35], "rpy": DOWN}}
    document = {"robot": "ur10", "safety_margin": 0.02, "start": start, "goal": goal}
    scene = parse_scene_file(document, "ur10 from a pose").scene
    constraint = OrientationConstraint(("x", "y"), 0.0873)
    starts: list[np.ndarray] = []

    def goal_test(q_start: np.ndarray) -> Callable[[np.ndarray], bool]:
        starts.append(q_start)
        return goal_on_constraint(ur10, constraint, q_start)

    problem = free_problem(scene, ur10, goal_test=goal_test)
    assert len(starts) == 1 and np.array_equal(starts[0], problem.motion.q_start)
    assert goal_on_constraint(ur10, constraint, problem.motion.q_start)(problem.motion.q_goal)


def test_a_carry_whose_nearest_goal_flips_the_elbow_ends_on_the_starts_branch() -> None:
    # before the goal was chosen on the constraint, this carry failed after minutes of search
    ur10 = ck.load_robot(example_robot("ur10"))
    document = {
        "robot": "ur10",
        "safety_margin": 0.02,
        "start": {"q": UR10_START},
        "task": [{"move": {"pose": {"xyz": [0.65, 0.4, 0.35], "rpy": DOWN}, "constraint": UPRIGHT}}],
    }
    read = parse_scene_file(document, "ur10 upright carry")
    task = plan_task(read.scene, read.task, ur10)
    assert task.accepted, task.problems
    end = task.trajectory(task.trajectory.knots[-1])
    assert np.sign(end[2]) == np.sign(UR10_START[2]) and np.sign(end[4]) == np.sign(UR10_START[4])


def test_a_carry_the_constraint_cannot_reach_stops_at_the_time_limit() -> None:
    # to the elbow-flipped solution, given as joint values: the free path cannot be bent onto the
    # constraint, and RRT-Connect on it would search its 1,500 samples (minutes); the scene's
    # time limit stops it, and the message says so
    ur10 = ck.load_robot(example_robot("ur10"))
    flipped = solve_ik(ur10, UR10_GOAL, np.array(UR10_START))
    document = {
        "robot": "ur10",
        "safety_margin": 0.02,
        "start": {"q": UR10_START},
        "planner": {"time_limit_s": 2.0},
        "task": [{"move": {"q": flipped.tolist(), "constraint": UPRIGHT}}],
    }
    read = parse_scene_file(document, "ur10 carry to a flipped elbow")
    with pytest.raises(
        NoSolutionError, match=r"by the time limit \(2 s; RRT-Connect on the constraint stopped"
    ):
        plan_task(read.scene, read.task, ur10)


def ur5_carry_to(goal_m: list[float], constraint: dict[str, Any]) -> SceneFile:
    """The UR5 moved to a pose, then carried under ``constraint`` to the tool position ``goal_m``."""
    document = {
        "robot": "ur5",
        "safety_margin": 0.02,
        "start": {"q": ARMS["ur5"]["start"]},
        "task": [
            {"move": {"pose": {"xyz": [0.5, -0.25, 0.3], "rpy": DOWN}}},
            {"move": {"tcp": goal_m, "constraint": constraint}},
        ],
    }
    return parse_scene_file(
        document, f"ur5 carry to a tool position held by {constraint.get('frame', 'tool')}"
    )


@pytest.mark.parametrize("frame", [None, "wrist_3_link"])
def test_a_carry_to_a_tool_position_ends_there_with_the_constrained_frame_upright(frame: str | None) -> None:
    # a tool position leaves the orientation to the IK, whose nearest solution turned the UR5's
    # tool 0.4 rad off the upright (refused as bad input); the constraint's orientation is meant.
    # The wrist's last link carries the tool frame: turning the tool turns it, so a constraint
    # on it turns the goal the same way (refused until stop 132: the IK's solution held it 1.03 rad off)
    goal_m = [0.45, 0.3, 0.3]
    read = ur5_carry_to(goal_m, UPRIGHT if frame is None else dict(UPRIGHT, frame=frame))
    task = plan_task(read.scene, read.task)
    assert task.accepted, task.problems
    robot = task.world.robot
    model, data = robot.model, robot.model.createData()
    held, tool = model.getFrameId(frame or robot.tcp_frame), model.getFrameId(robot.tcp_frame)
    carry = task.segments[1]
    axes = []
    for t in np.linspace(carry.t0, carry.t1, 50):  # pinocchio's forward kinematics, the oracle
        pin.framesForwardKinematics(model, data, task.trajectory(t))
        axes.append(data.oMf[held].rotation[:, 2].copy())
    np.testing.assert_allclose(data.oMf[tool].translation, goal_m, atol=1e-4)  # the goal's tolerance
    for axis in axes:  # the held z axis within the angle of where the carry started
        assert np.arccos(np.clip(axes[0] @ axis, -1.0, 1.0)) <= UPRIGHT["angle_rad"]


def test_a_tool_position_with_a_constraint_on_a_frame_the_tool_does_not_carry_is_refused() -> None:
    # the forearm does not turn with the tool: no tool orientation can turn it onto the constraint
    read = ur5_carry_to([0.45, 0.3, 0.3], dict(UPRIGHT, frame="forearm_link"))
    with pytest.raises(
        PlanningError,
        match=r"task\[1\] \(move\): the motion's goal: the IK solution of its tool position \[0\.45, 0\.3, "
        r"0\.3\] m holds 'forearm_link' [0-9.]+ rad from .* 'forearm_link' does not move with the tool frame "
        r"'tool0', so no tool orientation turns it: give the goal as joint values \(q\)",
    ):
        plan_task(read.scene, read.task)


def test_a_tool_position_the_arm_cannot_hold_upright_is_refused_naming_it() -> None:
    # the SO-101 (five joints) points its tool along its arm's vertical plane: held along the
    # world's x axis, its tool cannot reach a point off that plane
    so101 = ck.load_robot(example_robot("so101"))
    middle = ((so101.limits.lower + so101.limits.upper) / 2).tolist()
    document = {
        "robot": "so101",
        "safety_margin": 0.01,
        "start": {"q": middle},
        "task": [{"move": {"tcp": [0.2, 0.1, 0.15], "constraint": UPRIGHT}}],
    }
    read = parse_scene_file(document, "so101 held off its plane")
    with pytest.raises(
        PlanningError,
        match=r"task\[0\] \(move\): the motion's goal: the arm cannot turn 'gripper_frame_link' onto the "
        r"constraint's orientation about \['x', 'y'\] with the tool at \[0\.2, 0\.1, 0\.15\] m",
    ):
        plan_task(read.scene, read.task, so101)
