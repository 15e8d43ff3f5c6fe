"""Where the timing's moving averages take a sampled path (planning.curves.averaged_path)."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.bench.narrow_passages import ALL_KINDS
from planning.bench.scene_generator import generate_scenes
from planning.curves.averaged_path import QUADRATURE, averaged_samples, trapezoid_kernel
from planning.curves.velocity_caps import ROUNDS, TOLERANCE
from planning.pipeline.choose import foreseen_clear, verify
from planning.pipeline.planner import plan
from planning.pipeline.result import PlanResult

LIMITS = np.array([[1.0, 1.0], [2.0, 2.0], [20.0, 20.0]])  # v, a, j
WINDOW_S, SECOND_SHARE = 0.1, 0.125  # a / j, the timing's eighth


def averaged(points: np.ndarray) -> np.ndarray:
    return np.asarray(averaged_samples(points[None], LIMITS, WINDOW_S, ROUNDS, TOLERANCE, SECOND_SHARE)[0])


@pytest.mark.parametrize("share", [0.125, 0.25, 1.0])
def test_the_kernel_is_the_two_boxes_convolution(share: float) -> None:
    offsets, weights = trapezoid_kernel(WINDOW_S, share, QUADRATURE)
    assert weights.sum() == pytest.approx(1.0) and np.all(weights > 0)
    np.testing.assert_allclose(offsets, -offsets[::-1], atol=1e-15)  # symmetric
    np.testing.assert_allclose(weights, weights[::-1], rtol=1e-12)
    assert np.abs(offsets).max() < 0.5 * (1 + share) * WINDOW_S  # within the support
    # the variance of a sum of two uniform delays: (w^2 + (r w)^2) / 12
    variance = float(weights @ offsets**2)
    assert variance == pytest.approx((1 + share**2) * WINDOW_S**2 / 12, rel=2e-2)


def test_a_straight_path_stays_on_its_line() -> None:
    u = np.linspace(0.0, 1.0, 64)
    s = u**3 * (10 - 15 * u + 6 * u**2)  # at rest at both ends, as the planner's splines
    points = np.outer(s, [0.8, -0.3])
    moved = averaged(points)
    direction = np.array([0.8, -0.3]) / np.hypot(0.8, -0.3)
    off_line = moved - np.outer(moved @ direction, direction)
    assert np.abs(off_line).max() < 1e-12
    assert np.abs(moved - points).max() > 1e-4  # moved along it (in time), not held


def test_a_corner_is_cut_inside_its_bend() -> None:
    # (0, 0) -> (1, 0) -> (1, 1): every averaged point is a weighted mean of the path's
    # points, so it stays in their convex hull (x >= y, both in [0, 1]); the corner moves in
    leg = np.linspace(0.0, 1.0, 33)
    points = np.concatenate([np.column_stack([leg, 0 * leg]), np.column_stack([1 + 0 * leg[1:], leg[1:]])])
    moved = averaged(points)
    assert np.all(moved >= -1e-12) and np.all(moved <= 1 + 1e-12)
    assert np.all(moved[:, 0] >= moved[:, 1] - 1e-12)
    corner = moved[32]
    assert corner[0] < 1 - 1e-3 and corner[1] > 1e-3


def test_a_path_too_short_for_a_profile_is_returned_as_it_is() -> None:
    still = np.zeros((64, 2))
    np.testing.assert_array_equal(averaged(still), still)


@pytest.fixture(scope="module")
def pillars_87(robot: ck.Robot) -> PlanResult:
    """Generated pillars scene 87 of seed 87 (its 38th narrow scene), with the three waypoints it
    was chosen with: the refined best's fastest timing cuts a bend into the margin."""
    scene = generate_scenes(88, 87, robot, narrow=38, kinds=ALL_KINDS)[87]
    return plan(scene.with_planner(waypoints=3), robot)


def test_the_foreseen_samples_lie_on_the_timed_trajectory(pillars_87: PlanResult) -> None:
    # the oracle: the planner's own timing of the chosen path, sampled densely
    result = pillars_87
    objective, limits = result.problem.objective, result.problem.robot.limits
    x = result.waypoints[1:-1][:, objective.moving].ravel()[None]
    samples = objective.paths(objective.nodes(x)).samples
    foreseen = objective.paths.averaged(samples)
    assert foreseen is not None
    moved = foreseen[0]
    trajectory = result.trajectory
    executed = trajectory(np.linspace(trajectory.knots[0], trajectory.knots[-1], 20_000))

    def off_trajectory(points: np.ndarray) -> np.ndarray:  # [s at the velocity limits]
        gaps = np.abs(points[:, None, :] - executed[None]) / limits.velocity
        return np.asarray(gaps.max(axis=2).min(axis=1))

    shift = (np.abs(moved - samples[0]) / limits.velocity).max(axis=1)
    bent = shift > 0.2 * shift.max()
    assert shift.max() > 0.005  # a bend the averages cut by a visible amount (7 ms at the limits)
    assert np.median(off_trajectory(moved[bent])) < 0.1 * np.median(off_trajectory(samples[0][bent]))


def test_the_best_whose_cut_is_foreseen_is_timed_after_one_foreseen_clear(pillars_87: PlanResult) -> None:
    result = pillars_87
    problem, searched = result.problem, result.optimiser
    assert not foreseen_clear(problem, searched.x[None])[0]
    fastest = problem.duration.timings(problem, problem.objective.nodes(searched.x[None])[0]).first
    assert not verify(problem, fastest.trajectory, fastest.fit).accepted  # the oracle: it would fail
    assert result.metrics.candidates_verified == 1 and result.metrics.timing == "fastest"
    assert not np.array_equal(result.waypoints[1:-1][:, problem.moving].ravel(), searched.x)
