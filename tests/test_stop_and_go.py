"""A polyline followed at rest at each vertex: on the lines, within the limits, C3, through every vertex."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.curves.stop_and_go import joined, stop_and_go
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError


def distance_to_polyline(q: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """``(T,)`` each configuration's Euclidean distance to the nearest segment of ``vertices``."""
    a, b = vertices[:-1], vertices[1:]
    d = b - a
    share = np.clip(np.einsum("tsj,sj->ts", q[:, None] - a, d) / np.einsum("sj,sj->s", d, d), 0.0, 1.0)
    nearest = a + share[..., None] * d
    return np.asarray(np.linalg.norm(q[:, None] - nearest, axis=-1).min(axis=1))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_motion_stays_on_the_segments_and_stops_at_every_vertex(robot: ck.Robot, seed: int) -> None:
    limits = robot.limits
    vertices = np.random.default_rng(seed).uniform(limits.lower, limits.upper, (4, robot.nq))
    trajectory = stop_and_go(vertices, limits.velocity, limits.acceleration, limits.jerk)
    t = np.linspace(0.0, trajectory.duration, 4001)
    assert distance_to_polyline(trajectory(t), vertices).max() < 1e-9
    off = np.abs(trajectory(trajectory.knots)[:, None] - vertices).max(axis=2)  # (knots, vertices)
    at_vertex = np.flatnonzero(off.min(axis=1) < 1e-9)
    assert len(at_vertex) == len(vertices)  # each vertex is a knot, reached
    for r in (1, 2, 3):
        assert np.abs(trajectory(trajectory.knots[at_vertex], r)).max() < 1e-7  # at rest, jerk too (rounding)
    for r, limit in enumerate((limits.velocity, limits.acceleration, limits.jerk), start=1):
        assert np.all(trajectory.extrema(r).peak <= limit * (1.0 + 1e-9))
    jump, _ = trajectory.knot_jumps(4)
    assert np.abs(jump).max() < 1e-6 * max(limits.jerk)  # C3: position to jerk continuous


def test_repeated_vertices_are_passed_once_and_a_still_polyline_is_refused(robot: ck.Robot) -> None:
    limits = robot.limits
    a, b = limits.lower + 0.25 * limits.range, limits.lower + 0.75 * limits.range
    args = (limits.velocity, limits.acceleration, limits.jerk)
    once = stop_and_go(np.array([a, b]), *args)
    twice = stop_and_go(np.array([a, a, b, b]), *args)
    assert twice.duration == pytest.approx(once.duration, rel=1e-12)
    with pytest.raises(PlanningError, match="does not move"):
        stop_and_go(np.array([a, a]), *args)
    with pytest.raises(PlanningError, match="expected"):
        stop_and_go(a[None], *args)


def test_joined_trajectories_follow_one_another() -> None:
    first = Trajectory(np.array([1.0, 2.0]), np.array([[[0.0, 1.0]]]))  # 0 -> 1 over [1, 2] s
    second = Trajectory(np.array([0.0, 0.5, 1.0]), np.array([[[1.0, 2.0]], [[2.0, -2.0]]]))
    whole = joined([first, second])
    np.testing.assert_allclose(whole.knots, [0.0, 1.0, 1.5, 2.0])
    np.testing.assert_allclose(whole(np.array([0.5, 1.0, 1.25, 1.75, 2.0]))[:, 0], [0.5, 1.0, 1.5, 1.5, 1.0])
