"""Straight tool lines on the CPR, a Panda and a UR5, checked by an independent sampling every ms.

The oracle does not use the planner's deviation or verification: it evaluates the trajectory
every millisecond, puts the tool frame there by Pinocchio's forward kinematics, and measures
its distance from the segment between the start and goal poses and its rotation from the
slerp at the same progress, the joints' ranges, their speeds by finite differences of the
positions, and the joint torques by Pinocchio's RNEA with the payload.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning.errors import PlanningError, ToolLineBrokenError
from planning.outcome import classify
from planning.pipeline.verification import Requirements
from planning.task import LineMotion, LineTolerance, ToolLine, ToolPose, line_ik, plan_line
from planning.task.joint_ranges import LIMIT_GAIN

from .conftest import LIFT_SPEED_M_S

NO_MARGIN = Requirements(margin_m=0.0, step_m=0.01)


def sampled(motion: LineMotion, robot: ck.Robot) -> dict[str, float]:
    """The oracle: the largest deviations and limit usages every ms of the trajectory."""
    trajectory = motion.trajectory
    times = np.arange(trajectory.knots[0], trajectory.knots[-1], 1e-3)
    q = trajectory(times)
    model, data = robot.model, robot.model.createData()
    fid = model.getFrameId(motion.frame)
    start, goal = motion.start.placement(), motion.goal.placement()
    shift = goal.translation - start.translation
    turn = pin.log3(start.rotation.T @ goal.rotation)
    distance, angle = [], []
    for qk in q:
        pin.framesForwardKinematics(model, data, qk)
        pose = data.oMf[fid]
        sigma = np.clip((pose.translation - start.translation) @ shift / (shift @ shift), 0.0, 1.0)
        distance.append(np.linalg.norm(pose.translation - start.translation - sigma * shift))
        reference = start.rotation @ pin.exp3(sigma * turn)
        angle.append(np.linalg.norm(pin.log3(reference.T @ pose.rotation)))
    speed = np.abs(np.diff(q, axis=0)) / 1e-3 / robot.limits.velocity
    inside = (q >= robot.limits.lower - 1e-9) & (q <= robot.limits.upper + 1e-9)
    return {
        "distance_m": float(max(distance)),
        "angle_rad": float(max(angle)),
        "speed_usage": float(speed.max()),
        "inside": float(inside.all()),
    }


def test_a_cpr_line_lifts_straight_up_and_one_along_its_arm() -> None:
    robot = ck.load_cpr()
    world = ck.CollisionWorld(robot, [])
    q = robot.configuration([0.3, 0.3, 0.25, 0.2, 0.5])
    radial = 0.1 * np.array([np.cos(0.3), np.sin(0.3), 0.0])
    for by in ((0.0, 0.0, 0.12), tuple(radial)):
        motion = plan_line(world, q, ToolLine(by=by, offset_frame="base"), NO_MARGIN)
        found = sampled(motion, robot)
        assert found["distance_m"] <= 1e-3 and found["angle_rad"] <= 0.01
        assert found["distance_m"] <= motion.deviation.position_m  # the certified bound holds
        assert found["speed_usage"] <= 1.0 + 1e-6 and found["inside"]
        np.testing.assert_allclose(motion.trajectory(motion.trajectory.knots[0]), q, atol=1e-12)
        end = ck.frame_poses(robot, motion.trajectory(motion.trajectory.knots[-1]))
        np.testing.assert_allclose(end[:3, 3], motion.start.xyz + np.array(by), atol=1e-4)
        assert motion.verification.accepted


def test_a_panda_approaches_along_its_tool_axis_within_a_tight_tolerance() -> None:
    robot = ck.load_robot(example_robot("panda"))
    world = ck.CollisionWorld(robot, [])
    q = robot.configuration([0.1, 0.1, 0.1, -1.47, 0.1, 1.97, 0.1])
    tolerance = LineTolerance(position_m=2e-4, angle_rad=2e-3)
    line = ToolLine(by=(0.0, 0.0, 0.15), offset_frame="tool", tolerance=tolerance, tool_speed_m_s=0.25)
    motion = plan_line(world, q, line, NO_MARGIN)
    found = sampled(motion, robot)
    assert found["distance_m"] <= 2e-4 and found["angle_rad"] <= 2e-3
    start = ck.frame_poses(robot, q)
    end = ck.frame_poses(robot, motion.trajectory(motion.trajectory.knots[-1]))
    np.testing.assert_allclose(end[:3, 3] - start[:3, 3], start[:3, :3] @ [0.0, 0.0, 0.15], atol=2e-4)
    assert motion.deviation.tool_speed_m_s <= 0.25 + 1e-9
    assert motion.trajectory.duration >= 0.15 / 0.25  # the tool speed binds


def test_a_ur5_carrying_two_kilograms_turns_while_it_moves_within_its_torques() -> None:
    robot = ck.load_robot(example_robot("ur5"))
    world = ck.CollisionWorld(robot, [])
    q = robot.configuration([0.0, -1.57, 1.57, -1.57, -1.57, 0.0])
    start = ck.frame_poses(robot, q)
    turned = start[:3, :3] @ pin.exp3(np.array([0.0, 0.0, 0.4]))
    goal = pin.SE3(turned, start[:3, 3] + np.array([0.12, -0.08, 0.05]))
    dynamics = ck.robot_dynamics(robot, ck.Payload(mass_kg=2.0))
    required = Requirements(margin_m=0.0, step_m=0.01, dynamics=dynamics)
    motion = plan_line(world, q, ToolLine(to=ToolPose.of(goal)), required)
    found = sampled(motion, robot)
    assert found["distance_m"] <= 1e-3 and found["angle_rad"] <= 0.01
    times = np.arange(motion.trajectory.knots[0], motion.trajectory.knots[-1], 1e-3)
    trajectory = motion.trajectory
    torques = dynamics.torques(trajectory(times), trajectory.velocity(times), trajectory.acceleration(times))
    assert np.all(np.abs(torques) <= dynamics.effort * (1 + 1e-6))
    end = pin.SE3(ck.frame_poses(robot, trajectory(trajectory.knots[-1])))
    assert np.linalg.norm(pin.log6(goal.actInv(end)).vector) < 1e-3


def test_a_redundant_arm_walks_its_null_space_away_from_a_joint_limit() -> None:
    robot = ck.load_robot(example_robot("panda"))
    world = ck.CollisionWorld(robot, [])
    q = robot.configuration([-2.6973, 0.9042, -2.2187, -2.3293, 1.7752, 1.6829, 2.1835])
    line = ToolLine(by=(-0.0317, 0.0603, -0.1409), offset_frame="base")
    motion = plan_line(world, q, line, NO_MARGIN)  # joint 1 starts 0.2 rad from its limit
    found = sampled(motion, robot)
    assert found["distance_m"] <= 1e-3 and found["angle_rad"] <= 0.01 and found["inside"]
    with pytest.raises(ToolLineBrokenError, match="'panda_joint1' reaches its limit"):  # the plain walk
        line_ik._walk(robot, q, motion.frame, motion.geometry, line.tolerance, motion.path.sigma)


def test_where_the_walks_least_in_time_break_the_plain_steps_carry_the_line() -> None:
    """A Panda's joint 5 at 5 cm from its limit: the walks that favour its faster wrist joints break."""
    robot = ck.load_robot(example_robot("panda"))
    world = ck.CollisionWorld(robot, [])
    q = robot.configuration([-2.1216, -1.7128, -0.9084, -1.0179, 2.8378, 3.193, 1.1029])
    line = ToolLine(by=(-0.0759, -0.092, 0.0918), offset_frame="base")
    motion = plan_line(world, q, line, NO_MARGIN)
    found = sampled(motion, robot)
    assert found["distance_m"] <= 1e-3 and found["angle_rad"] <= 0.01 and found["inside"]
    for gain in (0.0, LIMIT_GAIN):  # the speed-scaled walks, with and without the pull from the limits
        with pytest.raises(ToolLineBrokenError, match="reaches its limit"):
            line_ik._walk(robot, q, motion.frame, motion.geometry, line.tolerance, motion.path.sigma, gain)


@pytest.mark.parametrize("by", [(0.0, 0.0, -0.05), (0.1, 0.0, 0.0), (0.0, 0.08, 0.05)])
def test_a_line_moves_the_fast_joints_and_leaves_a_slow_lift_where_it_is(
    ur5_on_a_lift: ck.Robot, by: tuple[float, float, float]
) -> None:
    """Each step of the walk is the least in time: the arm's joints (3.2 rad/s) carry the line.

    The oracle: the same robot with every joint as fast, whose steps are the plain least-squares
    steps; those move the lift (a metre of it weighs as a radian of a joint) by centimetres, which
    at its 0.02 m/s takes longer than the whole line does.
    """
    robot = ur5_on_a_lift
    fast = np.full(robot.nq, float(robot.limits.velocity.max()))
    equally_fast = dataclasses.replace(robot, limits=dataclasses.replace(robot.limits, velocity=fast))
    q = robot.configuration([0.2, 0.3, -1.2, 1.5, -1.9, 1.2, 0.0])
    line = ToolLine(by=by, offset_frame="base")
    motion = plan_line(ck.CollisionWorld(robot, []), q, line, NO_MARGIN)
    found = sampled(motion, robot)
    assert found["distance_m"] <= 1e-3 and found["angle_rad"] <= 0.01 and found["inside"]
    plain = plan_line(ck.CollisionWorld(equally_fast, []), q, line, NO_MARGIN)
    lift_m, plain_lift_m = np.ptp(motion.path.samples[:, 0]), np.ptp(plain.path.samples[:, 0])
    assert lift_m < 1e-3 and plain_lift_m > 0.04
    assert motion.trajectory.duration < plain_lift_m / LIFT_SPEED_M_S


def test_a_line_out_of_the_joint_range_breaks_at_the_share_it_reaches() -> None:
    robot = ck.load_cpr()
    world = ck.CollisionWorld(robot, [])
    q = robot.configuration([0.3, 0.3, 0.25, 0.2, 0.5])
    with pytest.raises(ToolLineBrokenError, match="joint 'd2' reaches its limit") as broken:
        plan_line(world, q, ToolLine(by=(0.0, 0.0, 0.5), offset_frame="base"), NO_MARGIN)
    assert broken.value.fraction == pytest.approx(0.3 / 0.5, abs=0.01)  # d2 has 0.3 m to its limit


def test_a_five_joint_arm_cannot_hold_its_orientation_across_its_arm() -> None:
    robot = ck.load_cpr()
    world = ck.CollisionWorld(robot, [])
    q = robot.configuration([0.3, 0.3, 0.25, 0.2, 0.5])
    sideways = 0.1 * np.array([-np.sin(0.3), np.cos(0.3), 0.0])  # the base turns, and the tool with it
    with pytest.raises(ToolLineBrokenError, match="cannot take the line's pose") as broken:
        plan_line(world, q, ToolLine(by=tuple(sideways), offset_frame="base"), NO_MARGIN)
    assert 0.0 <= broken.value.fraction < 0.5


def test_a_frame_too_few_joints_move_is_told_so_not_a_singularity() -> None:
    # the Panda's link3 is moved by its first three joints: its Jacobian has rank 3 everywhere,
    # and the message said only "it passes through a singularity of the arm"
    robot = ck.load_robot(example_robot("panda"))
    world = ck.CollisionWorld(robot, [])
    home = robot.configuration([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    model, data = robot.model, robot.model.createData()
    jacobian = pin.computeFrameJacobian(model, data, home, model.getFrameId("panda_link3"))
    assert np.linalg.matrix_rank(jacobian) == 3  # the oracle: Pinocchio's own Jacobian
    line = ToolLine(by=(0.05, 0.0, 0.0), offset_frame="base", frame="panda_link3")
    with pytest.raises(
        ToolLineBrokenError,
        match=r"frame 'panda_link3' is moved by 3 joint\(s\) \(panda_joint1, panda_joint2, panda_joint3\), "
        r"fewer than the 6 values of its pose the line holds: hold a frame the whole arm moves",
    ):
        plan_line(world, home, line, NO_MARGIN)


def test_an_obstacle_on_the_line_breaks_it_where_the_margin_is_first_crossed() -> None:
    robot = ck.load_cpr()
    q = robot.configuration([0.3, 0.3, 0.25, 0.2, 0.5])
    tcp = ck.frame_poses(robot, q)[:3, 3]
    ball = ck.Obstacle.sphere(0.02, tcp - np.array([0.0, 0.0, 0.1]), name="ball")
    world = ck.CollisionWorld(robot, [ball])
    required = Requirements(margin_m=0.01, step_m=0.01)
    with pytest.raises(ToolLineBrokenError, match="'ball'") as broken:
        plan_line(world, q, ToolLine(by=(0.0, 0.0, -0.15), offset_frame="base"), required)
    assert 0.2 < broken.value.fraction < 0.1 / 0.15  # stopped before the ball's surface less the margin


def test_bad_lines_are_refused_naming_the_field() -> None:
    with pytest.raises(PlanningError, match="exactly one of 'to'"):
        ToolLine()
    with pytest.raises(PlanningError, match="offset frame 'world'"):
        ToolLine(by=(0.0, 0.0, 0.1), offset_frame="world")
    with pytest.raises(PlanningError, match=r"position_m = 0.0 m must be a number in \[1e-06, 0.1\] m"):
        LineTolerance(position_m=0.0)
    with pytest.raises(PlanningError, match=r"angle_rad = nan rad must be a number in \[1e-05, 0.785398\]"):
        LineTolerance(angle_rad=float("nan"))
    with pytest.raises(PlanningError, match=r"line offset by = \[0.0, nan, 0.0\]; expected three"):
        ToolLine(by=(0.0, float("nan"), 0.0))
    with pytest.raises(PlanningError, match="quat_xyzw"):
        ToolPose((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 0.0))
    robot = ck.load_cpr()
    world = ck.CollisionWorld(robot, [])
    q = robot.configuration([0.3, 0.3, 0.25, 0.2, 0.5])
    with pytest.raises(PlanningError, match=r"moves 0 m and turns .* rad; it must move at least 0\.0001 m"):
        plan_line(world, q, ToolLine(by=(0.0, 0.0, 0.0)), NO_MARGIN)
    crate = ck.Obstacle.box(size=(0.4, 0.4, 0.4), xyz=tuple(ck.frame_poses(robot, q)[:3, 3]), name="crate")
    with pytest.raises(PlanningError, match="start configuration does not keep the clearances: 'tool' is"):
        plan_line(ck.CollisionWorld(robot, [crate]), q, ToolLine(by=(0.0, 0.0, 0.1)), NO_MARGIN)
    with pytest.raises(ck.CprKinError, match="unknown frame 'gripper'"):
        plan_line(world, q, ToolLine(frame="gripper", by=(0.0, 0.0, 0.1)), NO_MARGIN)


def test_a_broken_line_is_a_no_solution_outcome_exit_3_naming_the_share() -> None:
    outcome = classify(ToolLineBrokenError("joint 'd2' reaches its limit", 0.6))
    assert outcome.exit_code == 3
    assert "breaks after 60.0% of its length: joint 'd2' reaches its limit" in outcome.message
