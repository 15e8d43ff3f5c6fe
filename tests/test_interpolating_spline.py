"""The spline through samples, as a trajectory, against scipy's own interpolating B-spline."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from planning.curves.bspline_kernels import basis_derivatives, basis_work, knot_span
from planning.curves.interpolating_spline import not_a_knot, spline_through
from planning.errors import SplineError


@pytest.mark.parametrize("degree", [1, 3, 5, 7])
def test_the_trajectory_is_scipys_spline_with_its_derivatives(degree: int) -> None:
    rng = np.random.default_rng(degree)
    parameter = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0.0, 1.0, 12)]))
    samples = rng.normal(size=(14, 4))
    trajectory = spline_through(parameter, samples, degree)
    reference = make_interp_spline(parameter, samples, k=degree, axis=0)
    at = np.linspace(0.0, 1.0, 333)
    for r in range(min(degree, 4) + 1):
        expected = reference(at, nu=r)
        np.testing.assert_allclose(trajectory(at, r), expected, atol=1e-7 * np.abs(expected).max())
    np.testing.assert_allclose(trajectory(parameter), samples, atol=1e-9)
    assert trajectory.knots[0] == 0.0 and trajectory.knots[-1] == 1.0


def test_the_knots_are_scipys_not_a_knot_ones() -> None:
    sites = np.sort(np.random.default_rng(3).uniform(0.0, 2.0, 11))
    for degree in (1, 3, 5, 7):
        np.testing.assert_array_equal(not_a_knot(sites, degree), make_interp_spline(sites, sites, k=degree).t)


def test_a_long_one_dimensional_spline_as_the_path_parameter_takes_it() -> None:
    """2,049 unevenly spaced sites (an arc length), one value each: as scipy's, C4 across its knots."""
    rng = np.random.default_rng(7)
    length = np.cumsum(rng.uniform(0.2, 1.8, 2049)) * 1e-3
    u = np.linspace(0.0, 1.0, 2049) + 0.01 * np.sin(7.0 * np.linspace(0.0, 1.0, 2049))
    trajectory = spline_through(length, u[:, None])
    reference = make_interp_spline(length, u, k=5)
    at = np.linspace(length[0], length[-1], 5001)
    for r in range(3):
        expected = reference(at, nu=r)
        np.testing.assert_allclose(trajectory(at, r)[:, 0], expected, atol=1e-8 * np.abs(expected).max())
    inner = trajectory.knots[1:-1]
    for r in range(5):  # the pieces meet with their first four derivatives
        scale = np.abs(trajectory(inner, r)).max()
        ends = _powers(np.diff(trajectory.knots)[:-1], r)
        left = np.einsum("pjk,pk->pj", trajectory.coefficients[:-1], ends)
        np.testing.assert_allclose(left[:, 0], trajectory(inner, r)[:, 0], atol=1e-9 * scale)


def _powers(h: np.ndarray, r: int) -> np.ndarray:
    """``(P, 8)`` the weights of a piece's coefficients in its ``r``-th derivative at ``h`` past its start."""
    k = np.arange(8)
    falling = np.ones(8)
    for m in range(r):
        falling = falling * (k - m)
    return falling * np.where(k >= r, h[:, None] ** np.maximum(k - r, 0), 0.0)


def test_the_basis_sums_to_one_and_its_derivatives_to_zero() -> None:
    """A partition of unity at every point, so every derivative of the sum vanishes."""
    sites = np.sort(np.random.default_rng(5).uniform(0.0, 1.0, 20))
    knots = not_a_knot(sites, 5)
    for x in np.linspace(sites[0], sites[-1], 37):
        span = knot_span(knots, 5, len(sites), float(x))
        assert knots[span] <= x <= knots[span + 1]
        ders = basis_derivatives(knots, 5, span, float(x), 5, basis_work(5))
        assert ders[0].sum() == pytest.approx(1.0, abs=1e-12)
        np.testing.assert_allclose(ders[1:].sum(axis=1), 0.0, atol=1e-6 * np.abs(ders).max())


@pytest.mark.parametrize(
    ("parameter", "degree", "message"),
    [
        ([0.0, 0.5, 0.5, 0.7, 0.8, 0.9, 1.0], 5, r"parameter\[2\] = 0.5 follows 0.5"),
        ([0.0, 0.25, 0.5, 0.75, 1.0], 5, "more than 5 samples"),
        ([0.0, 0.2, 0.4, 0.6, 0.8, 1.0], 4, r"degree = 4; give one of \[1, 3, 5, 7\]"),
    ],
)
def test_bad_input_is_refused_by_name(parameter: list[float], degree: int, message: str) -> None:
    with pytest.raises(SplineError, match=message):
        spline_through(np.asarray(parameter), np.zeros((len(parameter), 2)), degree)
