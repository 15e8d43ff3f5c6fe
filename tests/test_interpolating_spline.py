"""The spline through samples, as a trajectory, against scipy's own evaluation of it."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.interpolate import make_interp_spline

from planning.curves.interpolating_spline import spline_through


@pytest.mark.parametrize("degree", [3, 5, 7])
def test_the_trajectory_is_scipys_spline_with_its_derivatives(degree: int) -> None:
    rng = np.random.default_rng(degree)
    parameter = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0.0, 1.0, 12)]))
    samples = rng.normal(size=(14, 4))
    trajectory = spline_through(parameter, samples, degree)
    reference = make_interp_spline(parameter, samples, k=degree, axis=0)
    at = np.linspace(0.0, 1.0, 333)
    for r in range(4):
        expected = reference(at, nu=r)
        np.testing.assert_allclose(trajectory(at, r), expected, atol=1e-7 * np.abs(expected).max())
    np.testing.assert_allclose(trajectory(parameter), samples, atol=1e-9)
    assert trajectory.knots[0] == 0.0 and trajectory.knots[-1] == 1.0
