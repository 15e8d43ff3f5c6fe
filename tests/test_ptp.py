from __future__ import annotations

import numpy as np
import pytest

from planning.curves.ptp import ptp_time


def test_ptp_time_is_the_sum_of_the_slowest_joints() -> None:
    nodes = np.array([[0.0, 0.0], [1.5, 0.1], [1.5, 0.7]])
    v, a = np.array([1.5, 0.5]), np.array([3.0, 2.0])
    expected = max(1.5 / 1.5 + 1.5 / 3.0, 2 * np.sqrt(0.1 / 2.0)) + max(0.0, 0.6 / 0.5 + 0.5 / 2.0)
    assert ptp_time(nodes, v, a) == pytest.approx(expected)
    batch = np.stack([nodes, nodes[::-1]])
    np.testing.assert_allclose(ptp_time(batch, v, a), [expected, expected])
