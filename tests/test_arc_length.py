from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.curves.arc_length import arc_length_path
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError

from .conftest import LIFT, PAPER_GOAL_TCP, PAPER_START_TCP, spline_path


@pytest.fixture(scope="module")
def curved(robot: ck.Robot) -> Trajectory:
    q0, q1 = ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP)
    return spline_path(np.array([q0, q0 + LIFT, q1 + LIFT * [-1, 1, 1, 1, 1], q1]))


def test_a_straight_line_has_the_length_of_its_chord_and_no_curvature(robot: ck.Robot) -> None:
    q0, q1 = ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP)
    velocity = robot.limits.velocity
    found = arc_length_path(spline_path(np.linspace(q0, q1, 5)), velocity)
    chord = float(np.linalg.norm((q1 - q0) / velocity))  # [s] at the velocity limits
    assert found.length[-1] == pytest.approx(chord, rel=1e-6)
    assert found.ds.sum() == pytest.approx(chord, rel=1e-6)
    direction = (q1 - q0) / np.linalg.norm((q1 - q0) / velocity)
    np.testing.assert_allclose(found.dq, np.broadcast_to(direction, found.dq.shape), atol=1e-9)
    np.testing.assert_allclose(found.ddq, 0.0, atol=1e-3)  # where the path stops at its ends: rounding


def test_the_path_runs_at_unit_speed_in_arc_length(robot: ck.Robot, curved: Trajectory) -> None:
    velocity = robot.limits.velocity
    found = arc_length_path(curved, velocity)
    speed = np.linalg.norm(found.dq / velocity, axis=1)
    np.testing.assert_allclose(speed, 1.0, atol=1e-9)
    # the derivative of a unit vector is orthogonal to it (in the metric scaled by the limits)
    along = np.sum(found.dq * found.ddq / velocity**2, axis=1)
    assert np.max(np.abs(along)) < 1e-6 * np.max(np.linalg.norm(found.ddq / velocity, axis=1))


def test_second_derivative_matches_finite_differences_of_the_first(
    robot: ck.Robot, curved: Trajectory
) -> None:
    found = arc_length_path(curved, robot.limits.velocity)
    middle = 0.5 * (found.ddq[1:] + found.ddq[:-1])
    difference = np.diff(found.dq, axis=0) / found.ds[:, None]
    inner = slice(len(middle) // 20, -len(middle) // 20)  # not where the path slows to a stop
    scale = np.max(np.abs(middle[inner]))
    assert np.max(np.abs(difference - middle)[inner]) < 0.01 * scale


def test_the_table_holds_the_path_at_its_arc_lengths(robot: ck.Robot, curved: Trajectory) -> None:
    found = arc_length_path(curved, robot.limits.velocity)
    u = np.linspace(curved.knots[0], curved.knots[-1], len(found.length))
    np.testing.assert_allclose(found.table, curved(u), atol=0)
    assert np.all(np.diff(found.length) >= 0) and found.length[0] == 0.0


def test_a_path_that_does_not_move_is_refused(robot: ck.Robot) -> None:
    q = ck.tcp_ik(robot, PAPER_START_TCP)
    with pytest.raises(PlanningError, match="does not move"):
        arc_length_path(spline_path(np.array([q, q, q])), robot.limits.velocity)
