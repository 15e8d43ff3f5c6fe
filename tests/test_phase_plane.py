from __future__ import annotations

import numpy as np
import pytest

from planning.curves.phase_plane import (
    _largest_x,
    _row_bounds,
    phase_plane_profile,
    profile_time,
    sampled_path_times,
)


def straight(delta: np.ndarray, points: int = 400) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A straight path q(u) = u delta, u in [0, 1]: q' = delta, q'' = 0."""
    d1 = np.tile(delta, (points, 1))
    return d1, np.zeros_like(d1), np.full(points - 1, 1.0 / (points - 1))


def trapezoid_time(distance: float, v: float, a: float) -> float:
    """Rest-to-rest time under |v| <= v, |a| <= a: cruise or not (the textbook's closed form)."""
    return distance / v + v / a if distance >= v * v / a else 2.0 * np.sqrt(distance / a)


@pytest.mark.parametrize(
    ("delta", "v", "a"),
    [
        ([1.68, 0.0, 0.0], [1.5, 0.5, 0.5], [3.0, 2.0, 2.0]),  # the paper's swing: cruises
        ([0.2, 0.1, 0.0], [1.5, 0.5, 0.5], [3.0, 2.0, 2.0]),  # short: a triangle
        ([1.0, 0.45, -0.3], [1.5, 0.5, 0.5], [3.0, 2.0, 2.0]),  # d2 limits the speed
    ],
)
def test_a_straight_line_takes_the_slowest_joints_trapezoid(
    delta: list[float], v: list[float], a: list[float]
) -> None:
    delta_arr, v_arr, a_arr = np.array(delta), np.array(v), np.array(a)
    d1, d2, du = straight(delta_arr)
    x = phase_plane_profile(d1, d2, du, v_arr, a_arr, np.zeros_like(d1))
    moving = np.abs(delta_arr) > 0
    # along a line, u'' and u' scale every joint alike: the slowest joint's trapezoid, with
    # the path limits v_j / |delta_j| and a_j / |delta_j|
    expected = trapezoid_time(
        1.0,
        np.min(v_arr[moving] / np.abs(delta_arr[moving])),
        np.min(a_arr[moving] / np.abs(delta_arr[moving])),
    )
    assert profile_time(x, du) == pytest.approx(expected, rel=2e-3)
    assert x[0] == x[-1] == 0.0


def test_the_profile_keeps_every_joint_within_its_limits_on_a_bend() -> None:
    u = np.linspace(0.0, 1.0, 600)
    # a quarter circle of radius 1 in two joints: q'' is the bend
    d1 = np.column_stack([-np.sin(u * np.pi / 2), np.cos(u * np.pi / 2)]) * np.pi / 2
    d2 = -np.column_stack([np.cos(u * np.pi / 2), np.sin(u * np.pi / 2)]) * (np.pi / 2) ** 2
    v, a = np.array([1.0, 1.0]), np.array([0.5, 0.5])
    du = np.diff(u)
    x = phase_plane_profile(d1, d2, du, v, a, np.zeros_like(d1))
    push = np.diff(x) / (2.0 * du)  # u'' on each step, applied from its first point
    velocity = d1 * np.sqrt(x)[:, None]
    acceleration = d2[:-1] * x[:-1, None] + d1[:-1] * push[:, None]
    assert np.max(np.abs(velocity) / v) <= 1.0 + 1e-9
    assert np.max(np.abs(acceleration) / a) <= 1.0 + 1e-6
    # on the bend the centripetal acceleration alone bounds the speed: |q''| x <= a
    assert np.max(x) <= 0.5 / (np.pi / 2) ** 2 * np.sqrt(2) + 1e-9


def test_more_room_is_never_slower() -> None:
    rng = np.random.default_rng(3)
    for _ in range(20):
        u = np.linspace(0, 1, 200)
        coefficients = rng.normal(size=(4, 3))
        q1 = np.column_stack([np.polyval(np.polyder(c[::-1]), u) for c in coefficients.T])
        q2 = np.column_stack([np.polyval(np.polyder(c[::-1], 2), u) for c in coefficients.T])
        v, a = rng.uniform(0.5, 2, 3), rng.uniform(0.5, 4, 3)
        du = np.diff(u)
        base = profile_time(phase_plane_profile(q1, q2, du, v, a, np.zeros_like(q1)), du)
        for which in range(2):
            room = [v, a]
            room[which] = room[which] * 1.3
            faster = phase_plane_profile(q1, q2, du, room[0], room[1], np.zeros_like(q1))
            assert profile_time(faster, du) <= base * (1 + 1e-9)


def test_sampled_paths_are_timed_in_arc_length() -> None:
    # the same straight line sampled uniformly, and sampled as a rest-to-rest spline does
    # (crowded at the ends): the same time, not the second one faster
    s = np.linspace(0.0, 1.0, 64)
    crowded = 3 * s**2 - 2 * s**3
    delta = np.array([1.68, 0.0, 0.0])
    points = np.stack([s[:, None] * delta, crowded[:, None] * delta])
    v, a = np.array([1.5, 0.5, 0.5]), np.array([3.0, 2.0, 2.0])
    times = sampled_path_times(points, v, a)
    assert times[0] == pytest.approx(trapezoid_time(1.68, 1.5, 3.0), rel=0.02)
    assert times[1] == pytest.approx(times[0], rel=0.02)
    still = np.zeros((1, 10, 3))
    assert sampled_path_times(still, v, a)[0] == 0.0


def test_the_backward_pass_may_skip_the_rows_bounds_below_the_limit_curve() -> None:
    """Below the maximum velocity curve (every row's bounds at once), the largest feasible
    ``x`` of a step is the same whether the rows' pairs are checked again or not."""
    rng = np.random.default_rng(5)
    for _ in range(20):
        g, rows = 12, 4
        d1, d2 = rng.normal(size=(g, rows)), rng.normal(size=(g, rows))
        d1[rng.random((g, rows)) < 0.1] = 0.0  # rows of their curvature term alone
        offset = 0.1 * rng.normal(size=(g, rows))
        a = rng.uniform(1.0, 3.0, rows)
        bounds = _row_bounds(d1, d2, offset, a)
        for point in range(g):
            limit = _largest_x(d1, d2, offset, bounds, point, a, 1e12, 0.0, 0.0)
            du, ahead = float(rng.uniform(0.01, 0.1)), float(rng.uniform(0.0, 2.0) * limit)
            checked = _largest_x(d1, d2, offset, bounds, point, a, limit, du, ahead)
            skipped = _largest_x(d1, d2, offset, bounds, point, a, limit, du, ahead, False)
            assert skipped == checked
