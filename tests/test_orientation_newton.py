"""The compiled projection onto an orientation constraint against the same rules written with Pinocchio."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from cpr_kin.model.packages import example_robot
from planning.task import OrientationConstraint
from planning.task.orientation_projection import DAMPING, HOLD_POSITION_M, NEWTON_STEPS, Projector

from .conftest import damped_step

FloatArray = np.ndarray


def reference_projection(
    projector: Projector, q: FloatArray, keep_position: bool
) -> tuple[FloatArray, float]:
    """The projection as Pinocchio's calls and numpy's solve, step by step (the module's rules)."""
    robot, constraint, reference = projector.robot, projector.constraint, projector.reference
    model, data, fid = robot.model, robot.data, robot.frame_id(projector.frame)
    weights = np.array([1.0 / HOLD_POSITION_M] * 3 + [1.0 / constraint.angle_rad] * 3)
    rows = slice(0, 6) if keep_position else slice(3, 6)
    lower, upper = robot.limits.lower, robot.limits.upper
    where, angle = None, math.inf
    for step in range(NEWTON_STEPS + 1):
        full = np.array(pin.computeFrameJacobian(model, data, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED))
        placement = data.oMf[fid]
        where = placement.translation.copy() if where is None else where
        error = constraint.error(placement.rotation, reference)
        angle = float(np.linalg.norm(error))
        if angle <= projector.aim_rad or step == NEWTON_STEPS:
            break
        turn = error * (1.0 - 0.9 * projector.aim_rad / angle)
        target = (np.concatenate([where - placement.translation, turn]) * weights)[rows]
        if constraint.free_axis is not None:
            axis = placement.rotation[:, constraint.free_axis]
            full[3:] = (np.eye(3) - np.outer(axis, axis)) @ full[3:]
        jacobian = (full * weights[:, None])[rows]
        size = max(float(np.sum(jacobian * jacobian)), 1.0)
        q = np.clip(q + damped_step(jacobian, target, DAMPING * math.sqrt(size)), lower, upper)
    return q, angle


ARMS = [
    pytest.param(lambda: ck.load_cpr(), id="cpr"),
    pytest.param(lambda: ck.load_robot(example_robot("panda")), id="panda"),
    pytest.param(lambda: ck.load_robot(example_robot("ur5")), id="ur5"),
]
CONSTRAINTS = [
    pytest.param(("x", "y"), math.radians(5.0), id="upright"),
    pytest.param(("x", "y", "z"), math.radians(10.0), id="whole"),
]


@pytest.mark.parametrize(("axes", "angle_rad"), CONSTRAINTS)
@pytest.mark.parametrize("load", ARMS)
@pytest.mark.parametrize("keep_position", [False, True])
def test_the_compiled_projection_takes_the_reference_steps(
    load: object, axes: tuple[str, ...], angle_rad: float, keep_position: bool
) -> None:
    robot = load()  # type: ignore[operator]
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    rng = np.random.default_rng(11)
    middle = rng.uniform(lower, upper)
    rotation = ck.frame_poses(robot, middle[None])[0][:3, :3]
    constraint = OrientationConstraint(axes, angle_rad)
    projector = Projector(robot, robot.tcp_frame, constraint, rotation)
    onto = 0
    for _ in range(12):
        q = np.clip(middle + rng.normal(scale=0.15, size=robot.nq), lower, upper)
        q_ref, angle_ref = reference_projection(projector, q, keep_position)
        q_new, angle_new = projector.project(q, keep_position)
        if angle_ref <= projector.aim_rad:  # a projection that fails wanders chaotically: no bits to agree on
            np.testing.assert_allclose(q_new, q_ref, atol=1e-9)
            assert angle_new == pytest.approx(angle_ref, rel=1e-9, abs=1e-12)
        assert np.all(q_new >= lower) and np.all(q_new <= upper)
        # the angle returned is the one forward kinematics measures at the configuration returned
        assert projector.angles(q_new[None])[0] == pytest.approx(angle_new, abs=1e-9)
        onto += angle_ref <= projector.aim_rad
    held = len(axes) + (3 if keep_position else 0)
    if held <= robot.nq:  # joints enough to hold what is asked
        assert onto >= 6  # most nearby configurations reach the manifold


def reference_steps(
    projector: Projector, q: FloatArray, aim: FloatArray, step_m: float, range_m: float, count: int
) -> tuple[list[FloatArray], bool, float]:
    """The walk's steps one projection at a time, in Python (the rules of ``Projector.steps``)."""
    radii = ck.motion_radii(projector.robot)

    def distance(a: FloatArray, b: FloatArray) -> float:
        return float(radii @ np.abs(a - b))

    steps: list[FloatArray] = []
    left, travelled = distance(q, aim), 0.0
    while len(steps) < count and left > 1e-9 and travelled < range_m:
        guess = aim if left <= step_m else q + (aim - q) * (step_m / left)
        stepped, angle = projector.project(guess)
        moved, remaining = distance(q, stepped), distance(stepped, aim)
        if angle > projector.aim_rad or moved > 2 * step_m or remaining >= left:
            return steps, True, travelled
        steps.append(stepped)
        q, left, travelled = stepped, remaining, travelled + moved
    return steps, False, travelled


@pytest.mark.parametrize("load", ARMS)
def test_the_compiled_steps_are_the_projections_one_at_a_time(load: object) -> None:
    robot = load()  # type: ignore[operator]
    lower, upper = np.asarray(robot.limits.lower), np.asarray(robot.limits.upper)
    rng = np.random.default_rng(13)
    middle = rng.uniform(lower, upper)
    rotation = ck.frame_poses(robot, middle[None])[0][:3, :3]
    projector = Projector(
        robot, robot.tcp_frame, OrientationConstraint(("x", "y"), math.radians(5.0)), rotation
    )
    radii = ck.motion_radii(robot)
    outcomes = set()
    for _ in range(10):
        start, _ = projector.project(np.clip(middle + rng.normal(scale=0.1, size=robot.nq), lower, upper))
        aim, _ = projector.project(np.clip(start + rng.normal(scale=0.3, size=robot.nq), lower, upper))
        for count, range_m in ((16, math.inf), (64, 0.05), (2000, math.inf)):
            expected, stuck_ref, travelled_ref = reference_steps(projector, start, aim, 0.01, range_m, count)
            steps, stuck, travelled = projector.steps(start, aim, 0.01, range_m, count, radii)
            assert stuck == stuck_ref and len(steps) == len(expected)
            if expected:
                np.testing.assert_allclose(steps, np.array(expected), atol=1e-9)
            assert travelled == pytest.approx(travelled_ref, rel=1e-9, abs=1e-12)
            reached = bool(expected) and float(radii @ np.abs(expected[-1] - aim)) <= 1e-9
            outcomes.add("stuck" if stuck else "reached" if reached else "counted or ranged")
    assert {"reached", "counted or ranged"} <= outcomes  # the walk's ends, both seen
