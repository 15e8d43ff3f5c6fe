"""The compiled Newton corrector of a tool line against the same rules written with Pinocchio."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.kinematics.tool_chain import ToolChain
from cpr_kin.model.packages import example_robot
from planning.task import LineTolerance
from planning.task.line_ik import DAMPING, IK_SHARE, NEWTON_STEPS, PROGRESS
from planning.task.line_newton import newton_to_pose

from .conftest import damped_step

FloatArray = np.ndarray
TOLERANCE = LineTolerance()
WEIGHTS = np.array([1.0 / TOLERANCE.position_m] * 3 + [1.0 / TOLERANCE.angle_rad] * 3)


@dataclass(frozen=True)
class Corrector:
    """The corrector on ``robot``'s ``frame`` within ``bounds``, its steps in coordinates ``q / scales``."""

    robot: ck.Robot
    frame: str
    bounds: tuple[FloatArray, FloatArray]
    scales: FloatArray

    def reference(self, q: FloatArray, target: pin.SE3) -> tuple[FloatArray, float]:
        """The corrector as Pinocchio's calls and numpy's solve, step by step."""
        model, data, fid = self.robot.model, self.robot.data, self.robot.frame_id(self.frame)
        excess = math.inf
        for _ in range(NEWTON_STEPS):
            pin.framesForwardKinematics(model, data, q)
            placement = data.oMf[fid]
            turn = placement.rotation @ pin.log3(placement.rotation.T @ target.rotation)
            error = np.concatenate([target.translation - placement.translation, turn]) * WEIGHTS
            size = max(float(np.linalg.norm(error[:3])), float(np.linalg.norm(error[3:])))
            if size > (1.0 - PROGRESS) * excess:
                break
            excess = size
            if excess <= IK_SHARE:
                break
            world_aligned = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            jacobian = pin.computeFrameJacobian(model, data, q, fid, world_aligned) * WEIGHTS[:, None]
            damping = DAMPING * math.sqrt(max(float(np.sum(jacobian**2)), 1.0))
            q = np.clip(q + self.scales * damped_step(jacobian * self.scales, error, damping), *self.bounds)
        return q, excess

    def compiled(self, q: FloatArray, target: pin.SE3) -> tuple[FloatArray, float]:
        """:func:`newton_to_pose`'s answer."""
        chain, tool = ToolChain.of(self.robot, self.frame).arrays
        rates = np.array([DAMPING, PROGRESS, IK_SHARE, NEWTON_STEPS], dtype=float)
        rules = (WEIGHTS, self.scales, *self.bounds, rates)
        return newton_to_pose(q, chain, tool, (target.translation, target.rotation), rules)


ARMS = [
    pytest.param(lambda: ck.load_cpr(), "tcp", id="cpr"),
    pytest.param(lambda: ck.load_robot(example_robot("panda")), None, id="panda"),
    pytest.param(lambda: ck.load_robot(example_robot("ur5")), None, id="ur5"),
    pytest.param(lambda: ck.load_robot(example_robot("panda")), "panda_link5", id="panda-link5"),
]


@pytest.mark.parametrize("speed_scaled", [False, True], ids=["plain", "speed-scaled"])
@pytest.mark.parametrize(("load", "frame"), ARMS)
def test_the_compiled_corrector_takes_the_reference_steps(
    load: object, frame: str | None, speed_scaled: bool
) -> None:
    robot = load()  # type: ignore[operator]
    frame = frame or robot.tcp_frame
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    scales = np.array(robot.limits.speed_scales) if speed_scaled else np.ones(robot.nq)
    corrector = Corrector(robot, frame, (lower, upper), scales)
    rng = np.random.default_rng(7)
    reached = 0
    for _ in range(20):
        wanted = rng.uniform(lower, upper)
        guess = np.clip(wanted + rng.normal(scale=0.05, size=robot.nq), lower, upper)
        target = pin.SE3(ck.frame_poses(robot, wanted[None], frame)[0])
        q_ref, excess_ref = corrector.reference(guess, target)
        q_new, excess_new = corrector.compiled(guess, target)
        np.testing.assert_allclose(q_new, q_ref, atol=1e-9)
        assert excess_new == pytest.approx(excess_ref, rel=1e-6, abs=1e-9)
        assert np.all(q_new >= lower) and np.all(q_new <= upper)
        reached += excess_new <= IK_SHARE
    # a 5 cm guess is within Newton's reach of a 6-joint pose; the 5-joint CPR reaches the poses
    # of its own configurations as well (its forward kinematics made them)
    assert reached >= 15


def test_a_pose_out_of_reach_settles_short_of_it_within_the_bounds() -> None:
    robot = ck.load_robot(example_robot("ur5"))
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    q = 0.5 * (lower + upper)
    target = pin.SE3(np.eye(3), np.array([3.0, 0.0, 0.5]))  # 3 m away: beyond a UR5's reach
    corrector = Corrector(robot, robot.tcp_frame, (lower, upper), np.array(robot.limits.speed_scales))
    q_ref, excess_ref = corrector.reference(q, target)
    q_new, excess_new = corrector.compiled(q, target)
    assert excess_new > 1e3  # metres over a millimetre's tolerance
    assert excess_new == pytest.approx(excess_ref, rel=1e-6)
    np.testing.assert_allclose(q_new, q_ref, atol=1e-6)
