from __future__ import annotations

import numpy as np

import cpr_kin as ck
from planning.curves.trajectory import Trajectory
from planning.utilisation import limit_usage

LIMITS = ck.JointLimits(
    names=("a", "b"),
    lower=np.array([-10.0, -10.0]),
    upper=np.array([10.0, 10.0]),
    velocity=np.array([3.0, 3.0]),
    acceleration=np.array([6.0, 6.0]),
    jerk=np.array([6.0, 6.0]),
)


def cubic() -> Trajectory:
    """Joint a: ``t^3`` on [0, 1] (velocity ``3 t^2``, acceleration ``6 t``, jerk 6); joint b: half."""
    coefficients = np.zeros((1, 2, 8))
    coefficients[0, 0, 3] = 1.0
    coefficients[0, 1, 3] = 0.5
    return Trajectory(knots=np.array([0.0, 1.0]), coefficients=coefficients)


def test_usage_over_time_matches_the_analytic_profile() -> None:
    usage = limit_usage(cubic(), LIMITS)
    t = usage.times
    np.testing.assert_allclose(usage.usage, np.column_stack([t**2, t, np.ones_like(t)]), atol=1e-12)
    assert np.all(usage.binding == 0)  # joint a moves twice as much as b
    # time averages: integral of t^2, t and 1 over [0, 1]
    np.testing.assert_allclose(usage.mean(), [1 / 3, 1 / 2, 1.0], atol=1e-6)
    # at 95 % or more: velocity for t >= sqrt(0.95), acceleration for t >= 0.95, jerk always
    near = usage.share_near_limit(0.95)
    np.testing.assert_allclose(near, [1 - np.sqrt(0.95), 0.05, 1.0, 1.0], atol=2e-3)


def test_phases_hold_each_span_peak_and_its_limit() -> None:
    usage = limit_usage(cubic(), LIMITS)
    phases = usage.phases(4)
    np.testing.assert_allclose(
        [(t0, t1) for t0, t1, *_ in phases], [(0, 0.25), (0.25, 0.5), (0.5, 0.75), (0.75, 1)]
    )
    for _, t1, peak, order, joint in phases:
        np.testing.assert_allclose(peak, [t1**2, t1, 1.0], atol=1e-12)  # increasing: the span's end
        assert peak[order] == max(peak) and joint == 0  # the jerk (at its limit throughout), then a tie


def test_a_planned_trajectory_uses_its_limits_no_more_than_its_exact_peaks(robot: ck.Robot) -> None:
    from planning import build_problem, solve
    from planning.io.bundled import paper_scene_path
    from planning.io.scene_file import load_scene

    scene = load_scene(paper_scene_path().parent / "shelf.yaml")  # free duration: timed as fast as allowed
    result = solve(build_problem(scene, robot))
    usage = limit_usage(result.trajectory, robot.limits)
    peaks = np.array(list(result.metrics.limit_utilisation.values()))
    assert np.all(usage.usage <= peaks + 1e-12)
    assert np.all(usage.usage.max(axis=0) >= peaks - 0.02)  # dense samples come near the exact peaks
    np.testing.assert_allclose(list(result.metrics.mean_limit_utilisation.values()), usage.mean())
