from __future__ import annotations

import numpy as np
from scipy.interpolate import BPoly

from planning.curves.hermite import ENERGY, HERMITE, HERMITE_INV, derivative_matrix


def test_hermite_step_matches_scipy_bpoly(rng: np.random.Generator) -> None:
    tau = np.linspace(0.0, 1.0, 101)
    for _ in range(20):
        data = rng.normal(size=8)  # x, x', x'', x''' at 0 then at 1
        coefficients = HERMITE_INV @ data
        reference = BPoly.from_derivatives([0.0, 1.0], [data[:4], data[4:]])
        for r in range(4):
            ours = np.polynomial.polynomial.polyval(tau, derivative_matrix(r) @ coefficients)
            np.testing.assert_allclose(ours, reference(tau, r), atol=1e-10 * (1 + np.abs(data).max()))


def test_hermite_matrix_is_paper_eq_14() -> None:
    # eq. 14 interleaves the rows: y_{i-1}, y_i, y'_{i-1}, y'_i, ...
    paper = np.array(
        [
            [1, 0, 0, 0, 0, 0, 0, 0],
            [1, 1, 1, 1, 1, 1, 1, 1],
            [0, 1, 0, 0, 0, 0, 0, 0],
            [0, 1, 2, 3, 4, 5, 6, 7],
            [0, 0, 2, 0, 0, 0, 0, 0],
            [0, 0, 2, 6, 12, 20, 30, 42],
            [0, 0, 0, 6, 0, 0, 0, 0],
            [0, 0, 0, 6, 24, 60, 120, 210],
        ]
    )
    order = [0, 4, 1, 5, 2, 6, 3, 7]
    np.testing.assert_array_equal(HERMITE[order], paper)


def test_energy_matches_quadrature(rng: np.random.Generator) -> None:
    nodes, weights = np.polynomial.legendre.leggauss(10)
    tau, w = 0.5 * (nodes + 1), 0.5 * weights
    for r in (1, 2, 3, 4):
        data = rng.normal(size=8)
        derivative = np.polynomial.polynomial.polyval(tau, derivative_matrix(r) @ HERMITE_INV @ data)
        assert data @ ENERGY[r] @ data == np.float64(w @ derivative**2).round(12) or np.isclose(
            data @ ENERGY[r] @ data, w @ derivative**2, rtol=1e-10
        )
