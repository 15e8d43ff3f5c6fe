"""The compiled band Cholesky against SciPy's (an independent implementation: LAPACK)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import cho_solve_banded, cholesky_banded

from planning.curves.banded_cholesky import band_cholesky, band_cholesky_solve


def random_band(n: int, kd: int, rng: np.random.Generator) -> np.ndarray:
    """Lower band storage of a random symmetric positive definite matrix."""
    a = np.zeros((n, n))
    for offset in range(kd + 1):
        values = rng.uniform(-1.0, 1.0, n - offset)
        a += np.diag(values, -offset)
        if offset:
            a += np.diag(values, offset)
    a += np.eye(n) * (np.abs(a).sum(axis=1).max() + 1.0)  # diagonally dominant
    return np.array([np.concatenate([np.diag(a, -k), np.zeros(k)]) for k in range(kd + 1)])


@pytest.mark.parametrize(("n", "kd"), [(1, 0), (5, 2), (40, 7), (200, 15)])
def test_factor_and_solve_match_lapack(n: int, kd: int) -> None:
    rng = np.random.default_rng(n + kd)
    band = random_band(n, kd, rng)
    factor, info = band_cholesky(band)
    assert info == 0
    expected = cholesky_banded(band, lower=True)
    np.testing.assert_allclose(factor, expected, rtol=1e-12, atol=1e-12)
    rhs = rng.standard_normal((n, 3))
    x = band_cholesky_solve(factor, rhs)
    np.testing.assert_allclose(x, cho_solve_banded((expected, True), rhs), rtol=1e-10, atol=1e-12)
    # and it solves the system: A x = rhs with A rebuilt from the band
    a = np.zeros((n, n))
    for k in range(kd + 1):
        a += np.diag(band[k, : n - k], -k) + (np.diag(band[k, : n - k], k) if k else 0.0)
    np.testing.assert_allclose(a @ x, rhs, atol=1e-10)


def test_a_matrix_not_positive_definite_reports_its_minor() -> None:
    band = np.array([[1.0, 1.0, 1.0], [2.0, 0.0, 0.0]])  # [[1, 2], [2, 1]] leads: minor 2 fails
    _, info = band_cholesky(band)
    assert info == 2
