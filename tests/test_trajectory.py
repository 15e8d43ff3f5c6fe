from __future__ import annotations

import re

import numpy as np
import pytest
from scipy.integrate import quad

from planning.curves.spline import fit_septic_spline
from planning.curves.spline_settings import SplineSettings
from planning.curves.trajectory import Trajectory
from planning.errors import PlanningError


@pytest.fixture()
def trajectory(rng: np.random.Generator) -> Trajectory:
    t = np.concatenate([[0.0], np.cumsum(rng.uniform(0.4, 1.5, 5))])
    f = rng.normal(size=(6, 3))
    return fit_septic_spline(t, f, SplineSettings(p=100.0, a=(0.0, 0.1, 1.0), ends="rest")).trajectory


def test_evaluation_matches_power_basis(trajectory: Trajectory) -> None:
    times = np.linspace(trajectory.knots[0], trajectory.knots[-1], 50)
    values = trajectory(times)
    for t, value in zip(times, values, strict=True):
        i = min(np.searchsorted(trajectory.knots, t, side="right") - 1, trajectory.n_segments - 1)
        expected = [
            np.polynomial.polynomial.polyval(t - trajectory.knots[i], c) for c in trajectory.coefficients[i]
        ]
        np.testing.assert_allclose(value, expected, atol=1e-13)
    assert trajectory(1.0).shape == (3,)
    assert values.shape == (50, 3)


def test_derivatives_match_finite_differences(trajectory: Trajectory) -> None:
    times = np.linspace(trajectory.knots[0] + 0.01, trajectory.knots[-1] - 0.01, 40)
    step = 1e-5
    for r in range(1, 5):
        central = (trajectory(times + step, r - 1) - trajectory(times - step, r - 1)) / (2 * step)
        np.testing.assert_allclose(
            trajectory(times, r), central, rtol=1e-5, atol=1e-5 * (1 + np.abs(central).max())
        )


def test_named_derivatives(trajectory: Trajectory) -> None:
    t = np.array([0.3, 1.7])
    np.testing.assert_array_equal(trajectory.position(t), trajectory(t, 0))
    np.testing.assert_array_equal(trajectory.velocity(t), trajectory(t, 1))
    np.testing.assert_array_equal(trajectory.acceleration(t), trajectory(t, 2))
    np.testing.assert_array_equal(trajectory.jerk(t), trajectory(t, 3))
    np.testing.assert_array_equal(trajectory.snap(t), trajectory(t, 4))


@pytest.mark.parametrize("derivative", [1, 2, 3])
def test_extrema_are_exact(trajectory: Trajectory, derivative: int) -> None:
    extrema = trajectory.extrema(derivative)
    dense_t = np.linspace(trajectory.knots[0], trajectory.knots[-1], 200_001)
    dense = trajectory(dense_t, derivative)
    scale = np.abs(dense).max()
    # no sample beats the exact extrema, and the dense sampling comes very close to them
    assert np.all(dense.min(axis=0) >= extrema.minimum - 1e-12 * scale)
    assert np.all(dense.max(axis=0) <= extrema.maximum + 1e-12 * scale)
    np.testing.assert_allclose(dense.min(axis=0), extrema.minimum, atol=1e-6 * scale)
    np.testing.assert_allclose(dense.max(axis=0), extrema.maximum, atol=1e-6 * scale)
    for j in range(trajectory.n_joints):
        assert trajectory(extrema.time_of_minimum[j], derivative)[j] == pytest.approx(
            extrema.minimum[j], abs=1e-12 * scale
        )
        assert trajectory(extrema.time_of_maximum[j], derivative)[j] == pytest.approx(
            extrema.maximum[j], abs=1e-12 * scale
        )
    np.testing.assert_array_equal(extrema.peak, np.maximum(-extrema.minimum, extrema.maximum))


def test_extrema_with_vanishing_leading_coefficients() -> None:
    # a single cubic segment stored in an order-8 layout (zeros on top): velocity extremum at t = 1
    c = np.zeros((1, 1, 8))
    c[0, 0, :4] = [0.0, 0.0, 3.0, -1.0]  # q = 3 t^2 - t^3, v = 6 t - 3 t^2
    trajectory = Trajectory(knots=np.array([0.0, 2.0]), coefficients=c)
    extrema = trajectory.extrema(1)
    assert extrema.maximum[0] == pytest.approx(3.0)
    assert extrema.time_of_maximum[0] == pytest.approx(1.0)
    assert extrema.minimum[0] == pytest.approx(0.0)


def test_integrated_squared_jerk_matches_quadrature(trajectory: Trajectory) -> None:
    for j in range(trajectory.n_joints):
        total = sum(
            quad(lambda t, j=j: trajectory(t, 3)[j] ** 2, lo, hi, epsabs=1e-12, epsrel=1e-12)[0]
            for lo, hi in zip(trajectory.knots[:-1], trajectory.knots[1:], strict=True)
        )
        assert trajectory.integrated_squared_jerk[j] == pytest.approx(total, rel=1e-9)


def test_time_scale_for_limits_reaches_a_limit_exactly(trajectory: Trajectory) -> None:
    velocity, acceleration, jerk = (
        np.array([1.5, 0.5, 0.5]),
        np.array([3.0, 2.0, 2.0]),
        np.array([15.0, 10.0, 10.0]),
    )
    s = trajectory.time_scale_for_limits(velocity, acceleration, jerk)
    scaled = trajectory.time_scaled(s)
    ratios = [
        float(np.max(scaled.extrema(r).peak / limit))
        for r, limit in ((1, velocity), (2, acceleration), (3, jerk))
    ]
    assert max(ratios) == pytest.approx(1.0, abs=1e-9)
    assert all(r <= 1.0 + 1e-9 for r in ratios)
    assert scaled.duration == pytest.approx(s * trajectory.duration)
    # velocity alone: s = peak / limit exactly
    s_v = trajectory.time_scale_for_limits(velocity)
    assert s_v == pytest.approx(float(np.max(trajectory.extrema(1).peak / velocity)))


@pytest.mark.parametrize("scale", [0.37, 1.0, 2.9])
def test_time_scaled_carries_the_extrema_found(
    trajectory: Trajectory, scale: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    late = Trajectory(trajectory.knots + 1.25, trajectory.coefficients)  # a start other than 0
    found = [late.extrema(r) for r in range(4)]
    scaled = late.time_scaled(scale)
    searched = Trajectory(scaled.knots, scaled.coefficients)  # the same trajectory, nothing known
    anew = [searched.extrema(r) for r in range(4)]

    def no_search(*args: object) -> None:
        raise AssertionError("the scaled trajectory searched its extrema again")

    monkeypatch.setattr("planning.curves.trajectory.extremum_candidates", no_search)
    for r, before in enumerate(found):
        carried = scaled.extrema(r)
        assert carried.derivative == r
        for name in ("minimum", "maximum"):
            np.testing.assert_allclose(getattr(carried, name), getattr(anew[r], name), rtol=1e-12, atol=1e-12)
        for name in ("time_of_minimum", "time_of_maximum"):  # a root where the value is flat: less sharp
            np.testing.assert_allclose(getattr(carried, name), getattr(anew[r], name), atol=1e-6)
        np.testing.assert_allclose(carried.peak, before.peak * scale**-r, rtol=1e-15)
        # read-only, as the searched ones are
        with pytest.raises(ValueError, match="read-only"):
            carried.maximum[0] = 0.0


def test_errors(trajectory: Trajectory) -> None:
    with pytest.raises(PlanningError, match=re.escape("time scale -1.0 must be a finite number > 0")):
        trajectory.time_scaled(-1.0)
    with pytest.raises(
        PlanningError, match=re.escape("velocity limits [0.0, 1.0, 1.0] must be finite and > 0")
    ):
        trajectory.time_scale_for_limits([0.0, 1.0, 1.0])
    with pytest.raises(PlanningError, match=re.escape("derivative order 9 must be in [0, 7]")):
        trajectory(0.0, 9)
    with pytest.raises(PlanningError, match=re.escape("time t = nan s must be a finite number")):
        trajectory([0.0, np.nan])  # came back as NaN positions
    with pytest.raises(PlanningError, match="must be at least two increasing times"):
        Trajectory(knots=np.array([0.0, 0.0]), coefficients=np.zeros((1, 1, 8)))
    still = Trajectory(knots=np.array([0.0, 1.0]), coefficients=np.zeros((1, 2, 8)))
    with pytest.raises(PlanningError, match="does not move"):
        still.time_scale_for_limits([1.0, 1.0])


def test_speed_bounds_hold_on_every_interval_and_never_exceed_the_peak(trajectory: Trajectory) -> None:
    times = np.linspace(trajectory.knots[0], trajectory.knots[-1], 41)
    bounds = trajectory.speed_bounds(times)
    assert bounds.shape == (40, trajectory.n_joints)
    for k in range(40):  # 200 samples inside each interval
        inside = np.abs(trajectory.velocity(np.linspace(times[k], times[k + 1], 200)))
        assert np.all(inside.max(axis=0) <= bounds[k] + 1e-12)
    assert np.all(bounds <= trajectory.extrema(1).peak)
    # at rest at both ends: the first and last intervals far below the peak
    assert np.all(bounds[[0, -1]] < 0.5 * trajectory.extrema(1).peak)


def test_a_piece_between_two_knots_is_the_trajectory_there(trajectory: Trajectory) -> None:
    t0, t1 = float(trajectory.knots[1]), float(trajectory.knots[3])
    piece = trajectory.between(t0, t1)
    times = np.linspace(t0, t1, 101)
    for r in range(4):
        np.testing.assert_allclose(piece(times, r), trajectory(times, r), rtol=1e-9, atol=1e-9)
    assert piece.knots[0] == t0 and piece.knots[-1] == t1
    with pytest.raises(PlanningError, match="are not two knots of the trajectory"):
        trajectory.between(t0 + 1e-3, t1)
