"""Timing on the path: the motion stays on a curved path, within every limit, at rest at both ends."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.curves.on_path_timing import time_on_path, time_on_path_marked
from planning.curves.path_timing import time_path
from planning.curves.trajectory import Trajectory
from tests.conftest import LIFT, limits_of, spline_path


def distance_to_path(path: Trajectory, points: np.ndarray) -> np.ndarray:
    """``(N,)`` each point's distance to the path's polyline of 20,000 chords (an upper bound)."""
    polyline = path(np.linspace(path.knots[0], path.knots[-1], 20_001))
    a, b = polyline[:-1], polyline[1:]
    out = np.empty(len(points))
    for k, point in enumerate(points):
        share = np.clip(np.sum((point - a) * (b - a), axis=1) / np.sum((b - a) ** 2, axis=1), 0.0, 1.0)
        out[k] = np.min(np.linalg.norm(a + share[:, None] * (b - a) - point, axis=1))
    return out


@pytest.fixture(scope="module")
def curved(robot: ck.Robot) -> Trajectory:
    start, goal = np.array([-1.0, 0.1, 0.1, 0.0, 0.0]), np.array([1.2, 0.3, 0.35, 0.5, -0.4])
    middle = 0.5 * (start + goal) + LIFT
    return spline_path(np.array([start, middle, goal]))


def test_a_curved_path_is_followed_where_the_joint_averages_cut_its_bend(
    robot: ck.Robot, curved: Trajectory
) -> None:
    on_path = time_on_path(curved, *limits_of(robot))
    cutting = time_path(curved, *limits_of(robot))
    times = np.linspace(on_path.knots[0], on_path.knots[-1], 400)
    off = distance_to_path(curved, on_path(times))
    assert off.max() < 1e-5  # rad or m: the knots are the path's points, the septic between them close
    cut = distance_to_path(curved, cutting(np.linspace(cutting.knots[0], cutting.knots[-1], 400)))
    assert cut.max() > 10 * off.max()  # what the other timing does to the same bend
    assert on_path.duration < 1.5 * cutting.duration  # and not much slower for it


def test_the_motion_keeps_every_limit_reaches_one_and_rests_at_both_ends(
    robot: ck.Robot, curved: Trajectory
) -> None:
    trajectory = time_on_path(curved, *limits_of(robot), node_step_s=0.05)
    usage = [trajectory.extrema(r).peak / limit for r, limit in enumerate(limits_of(robot), start=1)]
    assert max(u.max() for u in usage) == pytest.approx(1.0, abs=1e-9)
    for r in (1, 2, 3):
        np.testing.assert_allclose(trajectory(trajectory.knots[[0, -1]], r), 0.0, atol=1e-9)
    np.testing.assert_allclose(
        trajectory(trajectory.knots[[0, -1]]), curved(curved.knots[[0, -1]]), atol=1e-12
    )


def test_a_straight_path_is_timed_as_the_free_timing_times_it(robot: ck.Robot) -> None:
    start, goal = np.array([-1.0, 0.1, 0.1, 0.0, 0.0]), np.array([1.2, 0.3, 0.35, 0.5, -0.4])
    straight = spline_path(np.array([start, 0.5 * (start + goal), goal]))
    on_path = time_on_path(straight, *limits_of(robot))
    free = time_path(straight, *limits_of(robot))
    assert on_path.duration == pytest.approx(free.duration, rel=0.15)


def test_a_marked_motion_passes_each_mark_at_its_time_and_is_the_same_motion(
    robot: ck.Robot, curved: Trajectory
) -> None:
    plain = time_on_path(curved, *limits_of(robot))
    u0, u1 = curved.knots[0], curved.knots[-1]
    marks = u0 + np.array([0.2, 0.5, 0.9]) * (u1 - u0)
    marked = time_on_path_marked(curved, limits_of(robot), marks)
    assert np.all(np.diff(marked.times) > 0) and marked.times[0] > 0 and marked.times[-1] < plain.duration
    for t in marked.times:
        assert np.min(np.abs(marked.trajectory.knots - t)) < 1e-12  # a knot at each mark
    np.testing.assert_allclose(marked.trajectory(marked.times), curved(marks), atol=1e-6)
    times = np.linspace(0.0, plain.duration, 301)
    np.testing.assert_allclose(marked.trajectory(times), plain(times), atol=1e-9)
