from __future__ import annotations

import numpy as np
import pytest

from planning.curves.moving_average import arc_at_times, positions_at
from planning.errors import NoSolutionError


def test_positions_at_is_numpys_interp_of_each_column() -> None:
    rng = np.random.default_rng(7)
    length = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.1, 199))])
    table = rng.normal(size=(200, 4))
    inside = np.sort(rng.uniform(0.0, length[-1], 500))
    s = np.concatenate([[-0.5, 0.0], inside, length[[10, 11, 11, 50]], [length[-1], length[-1] + 1.0]])
    s.sort()  # non-decreasing, with repeats, grid points and points beyond both ends
    expected = np.column_stack([np.interp(s, length, column) for column in table.T])
    np.testing.assert_allclose(positions_at(s, length, table), expected, rtol=0, atol=1e-12)


def test_arc_at_times_is_exact_under_constant_acceleration_and_refuses_a_profile_that_stops() -> None:
    ds = np.full(100, 0.01)  # 1 m in 100 steps, from rest at 2 m/s^2: s = t^2, x = s'^2 = 4 s
    x = 4.0 * np.concatenate([[0.0], np.cumsum(ds)])
    s = arc_at_times(x, ds, 0.05)
    np.testing.assert_allclose(s, np.minimum((0.05 * np.arange(len(s))) ** 2, 1.0), atol=1e-12)
    assert s[-1] == pytest.approx(1.0, abs=1e-12) and len(s) == 21  # the last sample at the end, 1 s
    stops = x.copy()
    stops[40:42] = 0.0  # at rest over a step inside: it would take 1e9 s and as many samples
    with pytest.raises(NoSolutionError, match=r"cannot be timed: at the limits it takes .* more than 3600 s"):
        arc_at_times(stops, ds, 0.05)
