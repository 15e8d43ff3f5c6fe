"""A joint's shortest rest-to-rest move: by hand, and the distance its profile covers integrated."""

from __future__ import annotations

import numpy as np
import pytest

from cpr_kin.common.rest_to_rest import trapezoid_time


def test_trapezoid_by_hand() -> None:
    # v = 0.5, a = 2: cruise reached beyond v^2 / a = 0.125
    assert trapezoid_time(0.3, 0.5, 2.0) == pytest.approx(0.3 / 0.5 + 0.5 / 2.0)
    assert trapezoid_time(-0.1, 0.5, 2.0) == pytest.approx(2 * np.sqrt(0.1 / 2.0))
    assert trapezoid_time(0.125, 0.5, 2.0) == pytest.approx(0.5)  # both formulas meet
    assert trapezoid_time(0.0, 0.5, 2.0) == 0.0


def test_trapezoid_covers_the_distance() -> None:
    # integrate the profile the formula implies: accelerate, cruise, decelerate
    for distance in (0.05, 0.125, 0.4, 2.0):
        v, a = 0.5, 2.0
        total = float(trapezoid_time(distance, v, a))
        t = np.linspace(0.0, total, 200_001)
        peak = min(v, np.sqrt(distance * a))
        speed = np.minimum.reduce([a * t, np.full_like(t, peak), a * (total - t)])
        covered = np.trapezoid(speed, t)
        assert covered == pytest.approx(distance, rel=1e-6)
