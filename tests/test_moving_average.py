from __future__ import annotations

import numpy as np

from planning.curves.moving_average import positions_at


def test_positions_at_is_numpys_interp_of_each_column() -> None:
    rng = np.random.default_rng(7)
    length = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.1, 199))])
    table = rng.normal(size=(200, 4))
    inside = np.sort(rng.uniform(0.0, length[-1], 500))
    s = np.concatenate([[-0.5, 0.0], inside, length[[10, 11, 11, 50]], [length[-1], length[-1] + 1.0]])
    s.sort()  # non-decreasing, with repeats, grid points and points beyond both ends
    expected = np.column_stack([np.interp(s, length, column) for column in table.T])
    np.testing.assert_allclose(positions_at(s, length, table), expected, rtol=0, atol=1e-12)
