"""The pruned extremum candidates against a root search of every segment, and the roots themselves."""

from __future__ import annotations

import numpy as np
import pytest

from planning.curves.segment_extrema import extremum_candidates, real_roots_in
from planning.curves.spline import fit_septic_spline
from planning.curves.spline_settings import SplineSettings
from planning.curves.trajectory import derivative_coefficients


def _extremes(value: np.ndarray, local: np.ndarray, joints: int) -> tuple[np.ndarray, np.ndarray]:
    """Per joint, the smallest and largest value at the candidate local times (nan: none)."""
    values = np.zeros_like(local)
    for k in range(value.shape[1] - 1, -1, -1):
        values = values * local + value[:, k : k + 1]
    per_joint = values.reshape(-1, joints, local.shape[1]).transpose(1, 0, 2).reshape(joints, -1)
    return np.nanmin(per_joint, axis=1), np.nanmax(per_joint, axis=1)


@pytest.mark.parametrize("derivative", [0, 1, 2, 3])
def test_pruned_candidates_give_the_extrema_of_every_segment_searched(derivative: int) -> None:
    rng = np.random.default_rng(7)
    for _ in range(20):
        knots = np.concatenate([[0.0], np.cumsum(rng.uniform(0.05, 1.5, 30))])
        values = rng.normal(size=(31, 4)).cumsum(axis=0)
        spline = fit_septic_spline(knots, values, SplineSettings(p=50.0, a=(0.0, 0.1, 1.0), ends="rest"))
        coefficients = spline.trajectory.coefficients
        n, joints, order = coefficients.shape
        h = np.repeat(np.diff(knots), joints)
        value = derivative_coefficients(coefficients, derivative).reshape(n * joints, order)
        slope = derivative_coefficients(coefficients, derivative + 1).reshape(n * joints, order)
        every = np.concatenate([np.zeros((n * joints, 1)), h[:, None], real_roots_in(slope, h)], axis=1)
        pruned = extremum_candidates(value, slope, h, joints)
        assert np.isnan(pruned[:, 2:]).sum() > np.isnan(every[:, 2:]).sum()  # some segments skipped
        oracle = _extremes(value, every, joints)
        for ours, expected in zip(_extremes(value, pruned, joints), oracle, strict=True):
            np.testing.assert_array_equal(ours, expected)


def test_roots_of_known_polynomials() -> None:
    # (x - 0.5)(x - 2)(x + 1) = x^3 - 1.5 x^2 - 1.5 x + 1; x^2 + 1 has none; 3 x - 1.5 one
    coefficients = np.array([[1.0, -1.5, -1.5, 1.0], [1.0, 0.0, 1.0, 0.0], [-1.5, 3.0, 0.0, 0.0]])
    roots = real_roots_in(coefficients, np.array([3.0, 3.0, 0.4]))
    np.testing.assert_allclose(np.sort(roots[0][~np.isnan(roots[0])]), [0.5, 2.0])
    assert np.isnan(roots[1]).all()
    assert np.isnan(roots[2]).all()  # 0.5 lies beyond the upper end 0.4
