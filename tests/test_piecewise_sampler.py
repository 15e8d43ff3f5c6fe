"""The piecewise sampler against the trajectory's own evaluation (Horner per segment)."""

from __future__ import annotations

import numpy as np
import pytest

from planning.curves.piecewise_sampler import PiecewiseSampler, derivative_powers
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError


@pytest.mark.parametrize("derivatives", [0, 3])
def test_matches_trajectory_evaluation(derivatives: int) -> None:
    rng = np.random.default_rng(3)
    knots = np.cumsum(np.r_[0.5, rng.uniform(0.2, 1.5, 5)])
    coefficients = rng.normal(size=(5, 7, 8))
    times = np.sort(np.r_[knots, rng.uniform(knots[0], knots[-1], 200)])
    sampler = PiecewiseSampler(knots, times, 8, derivatives=derivatives)
    values = sampler(coefficients)
    assert values.shape == (derivatives + 1, len(times), 7)
    trajectory = Trajectory(knots, coefficients)
    for r in range(derivatives + 1):
        np.testing.assert_allclose(values[r], trajectory(times, derivative=r), rtol=1e-12, atol=1e-9)


def test_first_order_skips_the_lower_ones() -> None:
    rng = np.random.default_rng(4)
    knots = np.array([0.0, 0.8, 2.0])
    coefficients = rng.normal(size=(2, 3, 8))
    times = np.linspace(0.0, 2.0, 17)
    full = PiecewiseSampler(knots, times, 8, derivatives=3)(coefficients).copy()
    upper = PiecewiseSampler(knots, times, 8, derivatives=3, first=1)(coefficients)
    assert upper.shape == (3, 17, 3)
    np.testing.assert_array_equal(upper, full[1:])
    with pytest.raises(PlanningError, match=r"first = 4 must lie in \[0, derivatives = 3\]"):
        PiecewiseSampler(knots, times, 8, derivatives=3, first=4)


def test_derivative_powers_differentiate_a_monomial() -> None:
    t = np.array([0.0, 0.5, 2.0])
    # d^3/dt^3 t^5 = 60 t^2, and lower powers vanish
    powers = derivative_powers(t, 8, 3)
    np.testing.assert_allclose(powers[:, 5], 60 * t**2)
    np.testing.assert_array_equal(powers[:, :3], 0.0)


def test_buffer_is_reused_and_resized() -> None:
    sampler = PiecewiseSampler([0.0, 1.0, 2.0], np.linspace(0, 2, 9), 4)
    first = sampler(np.ones((2, 3, 4)))
    second = sampler(2 * np.ones((2, 3, 4)))
    assert np.shares_memory(first, second)  # same buffer, overwritten
    np.testing.assert_array_equal(first, second)
    larger = sampler(np.ones((2, 5, 4)))
    assert larger.shape == (1, 9, 5) and not np.shares_memory(larger, first)  # grown
    smaller = sampler(np.ones((2, 2, 4)))
    assert smaller.shape == (1, 9, 2) and np.shares_memory(smaller, larger)  # kept: large enough
    assert smaller.flags.c_contiguous
    expected = smaller[0, :, 0].copy()
    np.testing.assert_array_equal(sampler(np.ones((2, 1, 4)))[0, :, 0], expected)


@pytest.mark.parametrize(
    ("knots", "times", "pattern"),
    [
        ([0.0, 1.0], [0.5, 0.2], "non-decreasing"),
        ([0.0, 1.0], [0.5, 1.5], r"leave the knots \[0.0, 1.0\]"),
        ([1.0, 0.0], [0.5], "increasing times"),
    ],
)
def test_bad_input(knots: list[float], times: list[float], pattern: str) -> None:
    with pytest.raises(PlanningError, match=pattern):
        PiecewiseSampler(knots, times, 8)


def test_samplers_of_the_same_times_share_read_only_matrices_but_not_their_buffers() -> None:
    times = np.linspace(0.0, 2.0, 11)
    first = PiecewiseSampler([0.0, 1.0, 2.0], times, 8, derivatives=2)
    second = PiecewiseSampler(np.array([0.0, 1.0, 2.0]), times.copy(), 8, derivatives=2)
    assert first._blocks is second._blocks  # computed once
    with pytest.raises(ValueError):
        first._blocks[0][2][0][0, 0] = 1.0
    coefficients = np.random.default_rng(0).normal(size=(2, 3, 8))
    kept = first(coefficients)
    expected = kept.copy()
    second(2.0 * coefficients)  # another sampler's call leaves this one's result as it was
    np.testing.assert_array_equal(kept, expected)
    np.testing.assert_allclose(second(coefficients), expected, rtol=0, atol=0)
