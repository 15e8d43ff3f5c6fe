"""Ruckig's bound against the closed form of a jerk-limited rest-to-rest move."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import cpr_kin as ck
from planning.bench.ruckig_bound import free_space_bound, ruckig_duration
from planning.errors import PlanningError
from planning.io.bundled import paper_scene
from planning.pipeline.planner import plan


def test_a_long_single_joint_move_takes_the_closed_form_time() -> None:
    """Reaching both the velocity and the acceleration limit: ``d / v + v / a + a / j``."""
    v, a, j, d = 1.5, 3.0, 15.0, 4.0
    assert v / a + a / j < d / v  # long enough to cruise
    assert ruckig_duration([0.0], [d], [v], [a], [j]) == pytest.approx(d / v + v / a + a / j, rel=1e-9)


def test_a_short_move_that_never_reaches_the_acceleration_limit() -> None:
    """Four jerk phases of ``T / 4`` (``+j, -j, -j, +j``) cover ``d = j T^3 / 32``."""
    v, a, j, d = 10.0, 10.0, 15.0, 0.01
    assert ruckig_duration([0.0], [d], [v], [a], [j]) == pytest.approx((32 * d / j) ** (1 / 3), rel=1e-9)


def test_joints_are_synchronised_to_the_slowest() -> None:
    rng = np.random.default_rng(3)
    q0, q1 = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
    limits = [np.full(3, 1.5), np.full(3, 3.0), np.full(3, 15.0)]
    each = [ruckig_duration(q0[[k]], q1[[k]], *(x[[k]] for x in limits)) for k in range(3)]
    assert ruckig_duration(q0, q1, *limits) == pytest.approx(max(each), rel=1e-9)


@pytest.mark.parametrize(
    ("start", "limit", "match"),
    [([0.0, 0.0], [1.0], "shape"), ([0.0], [0.0], "> 0"), ([np.nan], [1.0], "finite")],
)
def test_bad_input_is_refused_with_the_reason(start: list[float], limit: list[float], match: str) -> None:
    with pytest.raises(PlanningError, match=match):
        ruckig_duration(start, [1.0], limit, [1.0], [1.0])


def test_a_planned_trajectory_is_never_shorter_than_its_problems_free_space_bound(robot: ck.Robot) -> None:
    result = plan(replace(paper_scene(), duration=None), robot)
    problem, limits = result.problem, robot.limits
    bound = free_space_bound(problem)
    assert bound == ruckig_duration(
        problem.q_start, problem.q_goal, limits.velocity, limits.acceleration, limits.jerk
    )
    assert bound <= result.trajectory.duration
