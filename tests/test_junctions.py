"""Motions joined at junctions that do not stop: C3, through each junction, rigid paths kept."""

from __future__ import annotations

import numpy as np
import pytest

from planning.curves.continuity import discontinuity
from planning.curves.interpolating_spline import spline_through
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError
from planning.task.junctions import Piece, by_chord, joined_motion, runs

LIMITS = (np.array([1.0, 1.0]), np.array([4.0, 4.0]), np.array([40.0, 40.0]))


def line(a: list[float], b: list[float]) -> Trajectory:
    sigma = np.linspace(0.0, 1.0, 11)
    return spline_through(sigma, np.asarray(a) + sigma[:, None] * (np.asarray(b) - np.asarray(a)))


def arc(a: list[float], b: list[float], bulge: float) -> Trajectory:
    sigma = np.linspace(0.0, 1.0, 41)
    points = np.asarray(a) + sigma[:, None] * (np.asarray(b) - np.asarray(a))
    points[:, 1] += bulge * np.sin(np.pi * sigma)
    return spline_through(sigma, points)


def test_runs_join_motions_and_cut_at_stops_and_where_two_rigid_meet() -> None:
    assert runs([False, True, None, True, False, True, True, False]) == [[0, 1], [3, 4, 5], [6, 7]]
    assert runs([None, False, None]) == []


@pytest.mark.parametrize("first_rigid", [False, True])
def test_a_joined_motion_is_c3_passes_each_junction_and_keeps_rigid_paths(first_rigid: bool) -> None:
    first = line([0.0, 0.0], [0.3, 0.0]) if first_rigid else arc([0.0, 0.0], [0.3, 0.0], 0.1)
    pieces = [
        Piece(first, first_rigid),
        Piece(arc([0.3, 0.0], [0.6, 0.4], -0.1), False),
        Piece(line([0.6, 0.4], [0.6, 0.7]), True),
    ]
    marked = joined_motion(pieces, LIMITS)
    trajectory = marked.trajectory
    np.testing.assert_allclose(trajectory(marked.times), [[0.3, 0.0], [0.6, 0.4]], atol=1e-6)
    assert np.abs(trajectory(marked.times, 1)).max() > 0.05  # passed without stopping
    for r in (1, 2, 3):
        np.testing.assert_allclose(trajectory(trajectory.knots[[0, -1]], r), 0.0, atol=1e-9)
    assert discontinuity(trajectory, ("x", "y")) is None  # C3 by check's own rule
    last = trajectory(np.linspace(marked.times[1], trajectory.duration, 200))
    assert np.abs(last[:, 0] - 0.6).max() < 1e-6  # the rigid line is followed as planned
    if first_rigid:
        head = trajectory(np.linspace(0.0, marked.times[0], 200))
        assert np.abs(head[:, 1]).max() < 1e-6
    for r, limit in enumerate(LIMITS, start=1):
        assert (trajectory.extrema(r).peak <= limit * (1 + 1e-9)).all()


def test_two_rigid_paths_are_not_joined() -> None:
    with pytest.raises(PlanningError, match="two rigid paths"):
        joined_motion([Piece(line([0, 0], [0.3, 0]), True), Piece(line([0.3, 0], [0.3, 0.3]), True)], LIMITS)


def test_a_path_by_its_chord_is_the_same_curve() -> None:
    timed = arc([0.0, 0.0], [0.5, 0.2], 0.1).time_scaled(3.0)
    again = by_chord(timed)
    assert again.knots[0] == 0.0 and again.knots[-1] == 1.0
    np.testing.assert_allclose(again(np.array([0.0, 1.0])), timed(timed.knots[[0, -1]]), atol=1e-12)
    speeds = np.linalg.norm(again(np.linspace(0.05, 0.95, 50), 1), axis=1)
    assert speeds.max() / speeds.min() < 1.2  # about its length: |q'| nearly constant
