"""The compiled walk along a tool line against the same rules written with Pinocchio and NumPy."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning.errors import ToolLineBrokenError
from planning.task import LineTolerance, ToolLine
from planning.task.joint_ranges import LIMIT_GAIN, LIMIT_ZONE, joint_range
from planning.task.line_ik import (
    DAMPING,
    LARGEST_JOINT_STEP,
    REACH_SHARE,
    _walk,
)
from planning.task.tool_line import BASE_FRAME, LineGeometry

from .conftest import damped_step
from .test_line_newton import Corrector

FloatArray = np.ndarray
TOLERANCE = LineTolerance()
WEIGHTS = np.array([1.0 / TOLERANCE.position_m] * 3 + [1.0 / TOLERANCE.angle_rad] * 3)


def reference_walk(
    robot: ck.Robot, q: FloatArray, geometry: LineGeometry, sigma: FloatArray, gain: float
) -> tuple[FloatArray, float, int]:
    """The walk step by step: the predictor, the pull in the null space, the corrector, the stops.

    Each least-squares step in the coordinates ``q / scales`` (the joints' speed scales), and
    the pull's null space that of those steps: ``pull - S step(J S, J pull)``.
    """
    model, data, fid = robot.model, robot.data, robot.frame_id(robot.tcp_frame)
    bounds = joint_range(robot)
    lower, upper = bounds
    middle, half = 0.5 * (lower + upper), 0.5 * (upper - lower)
    twist = np.concatenate([geometry.shift_m, geometry.start.rotation @ geometry.turn]) * WEIGHTS
    rotations = geometry.rotations(sigma)
    scales = np.array(robot.limits.speed_scales)
    samples, residual = [q], 0.0
    for k in range(1, len(sigma)):
        jacobian = pin.computeFrameJacobian(model, data, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        jacobian = jacobian * WEIGHTS[:, None]
        damping = DAMPING * math.sqrt(max(float(np.sum(jacobian * jacobian)), 1.0))  # the unscaled columns'
        step = scales * damped_step(jacobian * scales, twist * (sigma[k] - sigma[k - 1]), damping)
        if gain:
            depth = np.clip((np.abs(q - middle) / half - (1.0 - LIMIT_ZONE)) / LIMIT_ZONE, 0.0, 1.0)
            pull = depth * (middle - q)
            step += gain * (pull - scales * damped_step(jacobian * scales, jacobian @ pull, damping))
        guess = np.clip(q + step, *bounds)
        target = pin.SE3(rotations[k], geometry.start.translation + sigma[k] * geometry.shift_m)
        found, excess = Corrector(robot, robot.tcp_frame, bounds, scales).reference(guess, target)
        if excess > REACH_SHARE or np.abs(found - q).max() > LARGEST_JOINT_STEP:
            return np.array(samples), residual, k
        q, residual = found, max(residual, excess)
        samples.append(q)
    return np.array(samples), residual, -1


ARMS = [
    pytest.param(lambda: ck.load_cpr(), id="cpr"),
    pytest.param(lambda: ck.load_robot(example_robot("panda")), id="panda"),
    pytest.param(lambda: ck.load_robot(example_robot("ur5")), id="ur5"),
]


@pytest.mark.parametrize("gain", [0.0, LIMIT_GAIN])
@pytest.mark.parametrize("load", ARMS)
def test_the_compiled_walk_takes_the_reference_steps(load: object, gain: float) -> None:
    robot = load()  # type: ignore[operator]
    lower, upper = joint_range(robot)
    rng = np.random.default_rng(5)
    ends = {"whole": 0, "broken": 0}
    for _ in range(8):
        inside = 0.02 * (upper - lower)  # some starts in the outer zone, where the pull acts
        q = rng.uniform(lower + inside, upper - inside)
        start = pin.SE3(ck.frame_poses(robot, q))
        offset = (0.0, 0.0, float(rng.choice([-1.0, 1.0]) * rng.uniform(0.05, 0.3)))
        geometry = LineGeometry(start, ToolLine(by=offset, offset_frame=BASE_FRAME).goal(start))
        sigma = np.linspace(0.0, 1.0, 61)
        expected, residual_ref, broken_ref = reference_walk(robot, q, geometry, sigma, gain)
        try:
            samples, residual = _walk(robot, q, robot.tcp_frame, geometry, TOLERANCE, sigma, gain)
        except ToolLineBrokenError as broken:
            assert broken_ref > 0, "the compiled walk broke where the reference did not"
            assert broken.fraction == sigma[broken_ref - 1]
            ends["broken"] += 1
            continue
        assert broken_ref == -1, f"the reference broke at sample {broken_ref}, the compiled walk did not"
        np.testing.assert_allclose(samples, expected, atol=1e-9)
        assert residual == pytest.approx(residual_ref, rel=1e-6, abs=1e-12)
        ends["whole"] += 1
    assert ends["whole"] >= 2  # lines of 5 to 30 cm from configurations inside the ranges


def test_the_lines_rotations_are_its_poses_rotations() -> None:
    """The walk's targets by Rodrigues' formula, in a batch, against ``pose``'s exponential map."""
    start = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.2, 1.1), np.array([0.4, 0.1, 0.3]))
    goal = pin.SE3(pin.rpy.rpyToMatrix(-0.5, 0.4, 0.2), np.array([0.2, -0.1, 0.5]))
    geometry = LineGeometry(start, goal)
    sigma = np.linspace(0.0, 1.0, 17)
    for s, rotation in zip(sigma, geometry.rotations(sigma), strict=True):
        np.testing.assert_allclose(rotation, geometry.pose(float(s)).rotation, atol=1e-14)


def test_on_an_arm_of_five_joints_the_steps_least_in_time_are_the_plain_steps() -> None:
    """The CPR's five joints hold a line's six directions in the least-squares sense: a unique
    solution, whatever the joints' weights, so its walks agree up to the damping (1e-5 of the
    Jacobian's size)."""
    robot = ck.load_cpr()
    rng = np.random.default_rng(5)
    walked = 0
    for _ in range(8):
        q = rng.uniform(robot.limits.lower + 0.05, robot.limits.upper - 0.05)
        start = pin.SE3(ck.frame_poses(robot, q))
        geometry = LineGeometry(start, ToolLine(by=(0.0, 0.0, -0.05), offset_frame=BASE_FRAME).goal(start))
        sigma = np.linspace(0.0, 1.0, 41)
        try:
            least_in_time, _ = _walk(robot, q, robot.tcp_frame, geometry, TOLERANCE, sigma)
        except ToolLineBrokenError:
            continue
        plain, _ = _walk(robot, q, robot.tcp_frame, geometry, TOLERANCE, sigma, scales=np.ones(robot.nq))
        np.testing.assert_allclose(least_in_time, plain, atol=1e-7)
        walked += 1
    assert walked >= 4
