"""Bernstein bounds against exact extrema (roots of the next derivative) and identities."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import BPoly, PPoly

from planning.curves.polynomial_bounds import DerivativeBounds, bernstein_matrix
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError


def test_bernstein_coefficients_match_scipy() -> None:
    rng = np.random.default_rng(0)
    c = rng.normal(size=8)
    h = 0.7
    ours = bernstein_matrix(8, h) @ c
    power = PPoly(c[::-1, None], [0.0, h])  # scipy: highest power first
    theirs = BPoly.from_power_basis(power).c[:, 0]
    np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12)
    assert ours[0] == pytest.approx(c[0]) and ours[-1] == pytest.approx(float(power(h)))


def test_bounds_cover_the_exact_extrema_and_are_tight_on_average() -> None:
    rng = np.random.default_rng(1)
    knots = np.cumsum(np.r_[0.0, rng.uniform(0.3, 1.5, 4)])
    coefficients = rng.normal(size=(4, 30, 8))
    bounds = DerivativeBounds(knots, 8, (0, 1, 2, 3))(coefficients)
    trajectory = Trajectory(knots, coefficients)
    for row, r in enumerate((0, 1, 2, 3)):
        extrema = trajectory.extrema(r) if r else None
        if extrema is None:
            dense = trajectory(np.linspace(knots[0], knots[-1], 20001))
            exact = np.abs(dense).max(axis=0)
        else:
            exact = np.maximum(np.abs(extrema.minimum), np.abs(extrema.maximum))
        assert np.all(bounds[row] >= exact * (1 - 1e-12))
        assert np.median(bounds[row] / exact) < 2.0


def test_bound_is_exact_for_a_monotone_derivative() -> None:
    # q = t^3 on [0, 2]: velocity 3 t^2 peaks at the end, 12; jerk is the constant 6
    coefficients = np.zeros((1, 1, 8))
    coefficients[0, 0, 3] = 1.0
    bounds = DerivativeBounds([0.0, 2.0], 8, (1, 3))(coefficients)
    np.testing.assert_allclose(bounds[:, 0], [12.0, 6.0], rtol=1e-14)


def test_bad_input() -> None:
    with pytest.raises(PlanningError, match="increasing"):
        DerivativeBounds([1.0, 0.0], 8, (1,))
    with pytest.raises(PlanningError, match=r"orders in \[0, 7\]"):
        DerivativeBounds([0.0, 1.0], 8, (8,))
    with pytest.raises(PlanningError, match=r"expected \(1, M, 8\)"):
        DerivativeBounds([0.0, 1.0], 8, (1,))(np.zeros((2, 3, 8)))


def test_bounds_of_equal_knots_share_their_read_only_matrices() -> None:
    first = DerivativeBounds([0.0, 1.0, 2.5], 8, (1, 2, 3))
    second = DerivativeBounds(np.array([0.0, 1.0, 2.5]), 8, [1, 2, 3])
    assert first._matrices is second._matrices  # computed once
    assert not first._matrices.flags.writeable
    assert DerivativeBounds([0.0, 1.0, 2.0], 8, (1, 2, 3))._matrices is not first._matrices
