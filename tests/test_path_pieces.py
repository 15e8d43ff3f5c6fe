"""Cutting, reparameterising, bridging and joining piecewise polynomials: the same functions, exactly."""

from __future__ import annotations

import numpy as np
import pytest

from planning.curves.path_pieces import bridge, ends, joined_paths, piece, rescaled, split_at
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError


@pytest.fixture
def trajectory() -> Trajectory:
    rng = np.random.default_rng(3)
    return Trajectory(np.array([0.0, 0.4, 1.1, 1.5]), rng.normal(size=(3, 2, 8)))


def test_a_split_adds_knots_and_keeps_every_derivative(trajectory: Trajectory) -> None:
    cut = split_at(trajectory, [0.25, 1.3, 0.4])  # 0.4: a knot already
    np.testing.assert_allclose(cut.knots, [0.0, 0.25, 0.4, 1.1, 1.3, 1.5])
    times = np.linspace(0.0, 1.5, 301)
    for r in range(4):
        np.testing.assert_allclose(cut(times, r), trajectory(times, r), rtol=1e-10, atol=1e-8)
    with pytest.raises(PlanningError, match=r"t = 2 s is outside"):
        split_at(trajectory, [2.0])


def test_a_piece_is_the_function_over_its_span(trajectory: Trajectory) -> None:
    part = piece(trajectory, 0.3, 1.2)
    assert part.knots[0] == 0.3 and part.knots[-1] == 1.2
    times = np.linspace(0.3, 1.2, 91)
    np.testing.assert_allclose(part(times), trajectory(times), rtol=1e-10, atol=1e-9)


def test_a_rescaled_path_is_the_same_curve_and_its_derivatives_scale(trajectory: Trajectory) -> None:
    moved = rescaled(trajectory, 2.0, 3.0)  # [0, 1.5] -> [2, 5]: twice as long
    u = np.linspace(0.0, 1.5, 31)
    np.testing.assert_allclose(moved(2.0 + 2.0 * u), trajectory(u), rtol=1e-10, atol=1e-9)
    np.testing.assert_allclose(moved(2.0 + 2.0 * u, 1), trajectory(u, 1) / 2.0, rtol=1e-10, atol=1e-9)


def test_a_bridge_takes_both_ends_data_and_joins_c3(trajectory: Trajectory) -> None:
    first, second = piece(trajectory, 0.0, 0.5), rescaled(piece(trajectory, 1.0, 1.5), 0.8, 0.5)
    link = bridge(ends(first, 0.5), ends(second, 0.8), 0.5, 0.3)
    np.testing.assert_allclose(ends(link, 0.5), ends(first, 0.5), rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(ends(link, 0.8), ends(second, 0.8), rtol=1e-9, atol=1e-7)
    whole = joined_paths([first, link, second])
    for at in (0.5, 0.8):  # the joins: C3 (the random pieces' own knots are not)
        for r in range(4):
            left, right = whole(np.array([at - 1e-9]), r), whole(np.array([at + 1e-9]), r)
            np.testing.assert_allclose(left, right, rtol=1e-5, atol=1e-4)
