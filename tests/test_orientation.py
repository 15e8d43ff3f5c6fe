"""Orientation constraints: their angle, the rotation that corrects it, a certified bound between samples."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import cpr_kin as ck
from planning.curves.interpolating_spline import spline_through
from planning.curves.on_path_timing import time_on_path
from planning.errors import PlanningError
from planning.task.orientation import OrientationConstraint, orientation_deviation


def rotation(axis: list[float], angle: float) -> np.ndarray:
    return np.asarray(pin.exp3(np.asarray(axis, dtype=float) * angle))


@pytest.fixture(scope="module")
def rng() -> np.random.Generator:
    return np.random.default_rng(7)


def test_the_angle_of_an_upright_constraint_ignores_the_turn_about_its_free_axis() -> None:
    upright = OrientationConstraint(("x", "y"), 0.1)
    reference = np.eye(3)
    turned = np.stack([rotation([0, 0, 1], 1.3), rotation([1, 0, 0], 0.07), rotation([0, 1, 0], -0.2)])
    np.testing.assert_allclose(upright.angles(turned, reference), [0.0, 0.07, 0.2], atol=1e-12)
    whole = OrientationConstraint(("z", "x", "y"), 0.1)
    assert whole.axes == ("x", "y", "z") and whole.free_axis is None
    np.testing.assert_allclose(whole.angles(turned, reference), [1.3, 0.07, 0.2], atol=1e-12)


def test_the_tilt_is_the_angle_between_the_free_axes_by_arccos(rng: np.random.Generator) -> None:
    for free, held in ((2, ("x", "y")), (0, ("y", "z")), (1, ("x", "z"))):
        constraint = OrientationConstraint(held, 0.1)
        rotations = np.stack([pin.exp3(rng.normal(size=3)) for _ in range(20)])
        reference = np.asarray(pin.exp3(rng.normal(size=3)))
        expected = np.arccos(np.clip(rotations[:, :, free] @ reference[:, free], -1, 1))
        np.testing.assert_allclose(constraint.angles(rotations, reference), expected, atol=1e-7)


@pytest.mark.parametrize("axes", [("x", "y"), ("x", "y", "z"), ("y", "z")])
def test_the_error_turns_the_frame_onto_the_reference_by_its_angle(
    axes: tuple[str, ...], rng: np.random.Generator
) -> None:
    constraint = OrientationConstraint(axes, 0.1)
    for _ in range(20):
        frame, reference = (np.asarray(pin.exp3(rng.normal(size=3) * 0.8)) for _ in range(2))
        error = constraint.error(frame, reference)
        angle = constraint.angles(frame[None], reference)[0]
        assert np.linalg.norm(error) == pytest.approx(angle, abs=1e-9)
        corrected = pin.exp3(error) @ frame  # a world-aligned rotation acts from the left
        assert constraint.angles(corrected[None], reference)[0] < 1e-9


@pytest.mark.parametrize(
    ("axes", "angle", "message"),
    [
        (("x",), 0.1, r"axes = \['x'\]; give two or three different axes"),
        (("x", "x"), 0.1, r"axes = \['x', 'x'\]"),
        (("x", "w"), 0.1, r"axes = \['x', 'w'\]"),
        (("x", "y"), 2.0, r"constraint angle_rad = 2.0 rad must be a number in \[1e-05, 0.785398\] rad"),
    ],
)
def test_bad_constraints_are_refused_naming_the_value(
    axes: tuple[str, ...], angle: float, message: str
) -> None:
    with pytest.raises(PlanningError, match=message):
        OrientationConstraint(axes, angle)


def test_the_certified_angle_bounds_a_dense_sampling_of_a_turning_wrist() -> None:
    robot = ck.load_cpr()
    nodes = np.array([[0.0, 0.2, 0.2, -0.3, 0.0], [0.4, 0.25, 0.2, 0.4, 0.6], [0.9, 0.3, 0.25, -0.2, 1.2]])
    sigma = np.linspace(0.0, 1.0, 12)
    samples = np.array([np.interp(sigma, [0.0, 0.5, 1.0], nodes[:, j]) for j in range(5)]).T
    path = spline_through(sigma, samples)
    limits = robot.limits
    trajectory = time_on_path(path, limits.velocity, limits.acceleration, limits.jerk)
    reference = ck.frame_poses(robot, samples[0])[:3, :3]
    for axes in (("x", "y"), ("x", "y", "z")):
        constraint = OrientationConstraint(axes, 0.5)
        found = orientation_deviation(robot, robot.tcp_frame, constraint, reference, trajectory)
        times = np.linspace(trajectory.knots[0], trajectory.knots[-1], 40_001)  # every 0.1 ms or so
        dense = constraint.angles(ck.frame_poses(robot, trajectory(times))[:, :3, :3], reference)
        assert found.step_s <= 1e-3
        assert dense.max() <= found.angle_rad + 1e-12
        assert found.angle_rad - found.sampled_angle_rad <= 0.5 * constraint.angle_rad + 1e-12
        assert found.sampled_angle_rad == pytest.approx(dense.max(), abs=0.01)
