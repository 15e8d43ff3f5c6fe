"""The compiled IK descent against Pinocchio: its logarithm, its solve, its step, whole descents."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.kinematics.least_squares import damped_solve
from cpr_kin.kinematics.numerical_ik import PROGRESS, descent
from cpr_kin.kinematics.tool_chain import ToolChain, rotation_log
from cpr_kin.model.packages import example_robot

from .conftest import damped_step

FloatArray = np.ndarray


def random_rotation(rng: np.random.Generator, angle: float | None = None) -> FloatArray:
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    return np.asarray(pin.exp3(axis * (rng.uniform(0.0, math.pi) if angle is None else angle)))


def test_the_logarithm_is_pinocchios_from_zero_to_near_pi() -> None:
    rng = np.random.default_rng(3)
    angles = [None] * 40 + [0.0, 1e-9, 1e-5, 2e-4, 1.0, math.pi - 2e-3]
    for angle in angles:
        rotation = random_rotation(rng, angle)
        out = np.empty(3)
        measured = rotation_log(rotation, out)
        np.testing.assert_allclose(out, pin.log3(rotation), atol=1e-10)
        assert measured == pytest.approx(np.linalg.norm(pin.log3(rotation)), abs=1e-10)


@pytest.mark.parametrize("offset", [5e-4, 1e-7, 0.0])
def test_near_pi_the_logarithm_is_a_rotation_vector_of_the_rotation(offset: float) -> None:
    # the axis' sign is free at pi itself; the identity exp(log R) = R decides
    rng = np.random.default_rng(4)
    for _ in range(20):
        rotation = random_rotation(rng, math.pi - offset)
        out = np.empty(3)
        angle = rotation_log(rotation, out)
        np.testing.assert_allclose(pin.exp3(out), rotation, atol=1e-7)
        assert angle == pytest.approx(math.pi - offset, abs=1e-7)
        assert np.linalg.norm(out) == pytest.approx(angle, abs=1e-7)


@pytest.mark.parametrize("size", [1, 3, 6])
def test_the_damped_solve_is_numpys(size: int) -> None:
    rng = np.random.default_rng(size)
    for _ in range(10):
        jacobian = rng.normal(size=(size, 7))
        system = np.zeros((6, 6))
        system[:size, :size] = jacobian @ jacobian.T + 1e-6 * np.eye(size)
        rhs = np.zeros(6)
        rhs[:size] = rng.normal(size=size)
        expected = np.linalg.solve(system[:size, :size], rhs[:size])
        out = np.zeros(6)
        damped_solve(system.copy(), rhs, size, out)
        np.testing.assert_allclose(out[:size], expected, rtol=1e-8, atol=1e-10)


def reference_step(
    robot: ck.Robot, target: ck.IkTarget, q: FloatArray, scales: FloatArray, settings: ck.IkSettings
) -> FloatArray:
    """One damped least-squares step by Pinocchio's frame Jacobian (LOCAL_WORLD_ALIGNED) and NumPy.

    In the coordinates ``q / scales`` (a held joint's scale 0): ``S step(J S, e)``.
    """
    model, data, frame = robot.model, robot.data, robot.frame_id(robot.tcp_frame)
    pin.framesForwardKinematics(model, data, q)
    placement = data.oMf[frame]
    jacobian = pin.computeFrameJacobian(model, data, q, frame, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    error = target.position - placement.translation
    if target.rotation is not None:
        rotation = placement.rotation @ pin.log3(placement.rotation.T @ target.rotation)
        error = np.concatenate([error, rotation])
    else:
        jacobian = jacobian[:3]
    step = scales * damped_step(jacobian * scales, error, settings.damping)
    step = np.clip(step, -settings.max_step, settings.max_step)
    return np.asarray(np.clip(q + step, robot.limits.lower, robot.limits.upper))


ROBOTS = {
    "cpr": lambda: ck.load_cpr(),  # two prismatic joints
    "panda": lambda: ck.load_robot(example_robot("panda")),
    "ur5": lambda: ck.load_robot(example_robot("ur5")),
    # a frame halfway up the chain: the joints beyond it do not move it
    "panda_link4": lambda: dataclasses.replace(
        ck.load_robot(example_robot("panda")), tcp_frame="panda_link4"
    ),
}


@pytest.mark.parametrize("speed_scaled", [False, True], ids=["plain", "speed-scaled"])
@pytest.mark.parametrize("name", sorted(ROBOTS))
@pytest.mark.parametrize("pose", [True, False], ids=["pose", "position"])
def test_one_step_is_the_damped_least_squares_step_on_pinocchios_jacobian(
    name: str, pose: bool, speed_scaled: bool
) -> None:
    robot = ROBOTS[name]()
    speeds = np.array(robot.limits.speed_scales) if speed_scaled else None
    rng = np.random.default_rng(11)
    settings = ck.IkSettings(iterations=1, damping=0.05, max_step=0.2)
    for k in range(8):
        q, wanted = rng.uniform(robot.limits.lower, robot.limits.upper, (2, robot.nq))
        tool = ck.frame_poses(robot, wanted[None])[0]
        target = ck.IkTarget(tool[:3, 3], tool[:3, :3] if pose else None)
        free = np.ones(robot.nq, dtype=bool)
        free[k % robot.nq] = k % 2 == 0  # every other draw holds a joint
        stepped, steps = descent(robot, target, free, settings, speeds)(q)
        assert steps == 1
        scales = free * (1.0 if speeds is None else speeds)
        np.testing.assert_allclose(stepped, reference_step(robot, target, q, scales, settings), atol=1e-10)
        assert free[k % robot.nq] or stepped[k % robot.nq] == q[k % robot.nq]


def test_the_tool_chain_moves_the_tool_by_the_joints_it_hangs_from() -> None:
    robot = ROBOTS["panda_link4"]()
    tool = ToolChain.of(robot)
    assert tool.moves_tool.tolist() == [True] * 4 + [False] * 3
    pin.framesForwardKinematics(robot.model, robot.data, pin.neutral(robot.model))
    frame = robot.model.frames[robot.frame_id("panda_link4")]
    assert tool.joint == frame.parentJoint - 1


def reference_descent(
    robot: ck.Robot, target: ck.IkTarget, q: FloatArray, settings: ck.IkSettings
) -> tuple[FloatArray, int]:
    """The descent's rules in Python on Pinocchio, step by step (numerical_ik's docstring)."""
    frame, least, stuck, steps = robot.frame_id(robot.tcp_frame), math.inf, 0, 0
    free = np.ones(robot.nq)
    for _ in range(settings.iterations):
        pin.framesForwardKinematics(robot.model, robot.data, q)
        excess = target.excess(robot.data.oMf[frame])
        if excess <= 1.0:
            break
        if excess < (1.0 - PROGRESS) * least:
            least, stuck = excess, 0
        else:
            stuck += 1
            if stuck >= settings.patience:
                break
        q, steps = reference_step(robot, target, q, free, settings), steps + 1
    return q, steps


@pytest.mark.parametrize("name", ["cpr", "panda", "ur5"])
def test_whole_descents_end_where_pinocchios_steps_end(name: str) -> None:
    robot, settings = ROBOTS[name](), ck.IkSettings()
    rng = np.random.default_rng(12)
    free = np.ones(robot.nq, dtype=bool)
    reached = 0
    for k in range(12):
        q, wanted = rng.uniform(robot.limits.lower, robot.limits.upper, (2, robot.nq))
        tool = ck.frame_poses(robot, wanted[None])[0]
        target = ck.IkTarget(tool[:3, 3], tool[:3, :3] if k % 2 else None)
        expected, expected_steps = reference_descent(robot, target, q, settings)
        ended, steps = descent(robot, target, free, settings)(q)
        assert steps == expected_steps
        np.testing.assert_allclose(ended, expected, atol=1e-8)
        reached += target.reached(pin.SE3(ck.frame_poses(robot, ended[None])[0]))
    assert 4 <= reached <= 10  # some starts converge, some stall: both ends of a descent ran
