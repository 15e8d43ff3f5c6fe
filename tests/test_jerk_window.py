from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.curves.arc_length import arc_length_path
from planning.curves.jerk_window import averaged_jerk_usage, needed_window, sampled_path_durations
from planning.curves.moving_average import averaged_motion
from planning.curves.path_timing import SECOND_SHARE
from planning.curves.velocity_caps import ROUNDS, TOLERANCE, capped_motion

from .conftest import LIFT, limits_of, spline_path

STEP_S = 1e-4


def positions_of(times: np.ndarray, velocity: np.ndarray) -> np.ndarray:
    """Positions every :data:`STEP_S` of a motion whose velocity is linear between ``times``."""
    grid = np.arange(0.0, times[-1] + STEP_S / 2, STEP_S)
    speeds = np.column_stack([np.interp(grid, times, column) for column in velocity.T])
    steps = (speeds[1:] + speeds[:-1]) / 2 * STEP_S  # trapezoids: exact for a linear velocity
    return np.vstack([np.zeros(speeds.shape[1]), np.cumsum(steps, axis=0)])


def timing_usage(
    times: np.ndarray, velocity: np.ndarray, jerk: np.ndarray, window_s: float, second: float
) -> float:
    """The jerk usage of the timing's own moving averages (the oracle), on a fine time grid."""
    motion = averaged_motion(positions_of(times, velocity), window_s, STEP_S, second)
    return float(np.max(np.abs(motion[3, 2:-2]) / jerk))


@pytest.mark.parametrize("second", [SECOND_SHARE, 0.25])
def test_the_averaged_jerk_is_the_timings_own_on_random_profiles(second: float) -> None:
    rng = np.random.default_rng(3)
    jerk = np.array([10.0, 20.0])
    for _ in range(10):
        times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.02, 0.15, 14))])
        velocity = rng.uniform(-1.0, 1.0, (times.size, 2))
        velocity[[0, -1]] = 0.0  # from rest to rest
        window_s = float(rng.uniform(0.1, 0.3))
        expected = timing_usage(times, velocity, jerk, window_s, second)
        assert averaged_jerk_usage(times, velocity, jerk, window_s, second) == pytest.approx(
            expected, rel=0.01
        )


def formula_usage(
    times: np.ndarray, velocity: np.ndarray, jerk: np.ndarray, window_s: float, second: float
) -> float:
    """The module docstring's jerk at every instant where one of its four velocities meets a grid
    point, each velocity interpolated by NumPy (0 before the start and after the end)."""
    delays = np.array([0.0, second, 1.0, 1.0 + second]) * window_s
    signs = np.array([1.0, -1.0, -1.0, 1.0])
    instants = (times[:, None] + delays[None, :]).ravel()
    usage = 0.0
    for j in range(velocity.shape[1]):
        speed = [np.interp(instants - delay, times, velocity[:, j], left=0.0, right=0.0) for delay in delays]
        averaged = np.tensordot(signs, np.array(speed), axes=1) / (second * window_s**2)
        usage = max(usage, float(np.max(np.abs(averaged))) / jerk[j])
    return usage


@pytest.mark.parametrize("second", [0.25, 0.3, 1.0])
def test_the_averaged_jerk_is_the_formulas_at_every_breakpoint(second: float) -> None:
    """Shifts that coincide (a quarter: 9 distinct of 16) or do not (0.3: 13) give the formula's value."""
    rng = np.random.default_rng(11)
    for _ in range(20):
        times = np.concatenate([[0.0], np.cumsum(rng.uniform(0.005, 0.2, int(rng.integers(2, 40))))])
        velocity = rng.uniform(-2.0, 2.0, (times.size, 3))
        velocity[[0, -1]] = 0.0  # from rest to rest
        jerk = rng.uniform(5.0, 50.0, 3)
        window_s = float(rng.uniform(0.01, 0.5))
        assert averaged_jerk_usage(times, velocity, jerk, window_s, second) == pytest.approx(
            formula_usage(times, velocity, jerk, window_s, second), rel=1e-12
        )


def test_a_move_too_short_to_cruise_doubles_the_window() -> None:
    """Bang-bang (``+a`` then ``-a``): the first average's jerk is ``2 a / w`` for a window of
    ``w``, so the usage is 2 at ``w = a / j`` and 1 at twice it; the motion lasts ``T + 2.5 a / j``."""
    a, j, half_s = 2.0, 10.0, 0.6
    times = np.array([0.0, half_s, 2 * half_s])
    velocity = np.array([[0.0], [a * half_s], [0.0]])
    w = a / j
    assert averaged_jerk_usage(times, velocity, np.array([j]), w, SECOND_SHARE) == pytest.approx(
        2.0, rel=1e-12
    )
    window, usage = needed_window(times, velocity, np.array([j]), w, ROUNDS, TOLERANCE, SECOND_SHARE)
    assert window == pytest.approx(2 * w) and usage == pytest.approx(1.0)


def test_a_cruise_longer_than_the_window_keeps_it() -> None:
    a, j, ramp_s, cruise_s = 2.0, 10.0, 0.5, 0.4
    times = np.array([0.0, ramp_s, ramp_s + cruise_s, 2 * ramp_s + cruise_s])
    velocity = np.array([[0.0], [a * ramp_s], [a * ramp_s], [0.0]])
    window, usage = needed_window(times, velocity, np.array([j]), a / j, ROUNDS, TOLERANCE, SECOND_SHARE)
    assert window == a / j and usage == pytest.approx(1.0, rel=1e-12)


def test_durations_are_the_uncapped_timings_of_the_same_paths(
    robot: ck.Robot, lines: list[tuple[np.ndarray, np.ndarray]]
) -> None:
    """Within 1 % of what the timing's moving averages take along the uncapped phase-plane
    profile of the fine path, on 256 samples of it (the estimate checks the jerk with a
    second average of at least a quarter window, ``SAMPLED_SECOND_SHARE``, the timing with
    its eighth); within 5 % on the fitness's 64 (coarser samples cut the sharper bends of the
    lifted paths)."""
    limits = np.stack(limits_of(robot))
    window_s = float(np.max(limits[1] / limits[2]))
    paths = [spline_path(np.linspace(q0, q1, 5)) for q0, q1 in lines]
    paths += [spline_path(np.array([q0, q0 + LIFT, q1 + LIFT * [-1, 1, 1, 1, 1], q1])) for q0, q1 in lines]
    for path in paths:
        timed = capped_motion(arc_length_path(path, limits[0]), limits, SECOND_SHARE, 1.0).duration_s
        for count, tolerance in ((256, 0.01), (64, 0.05)):
            samples = path(np.linspace(path.knots[0], path.knots[-1], count))
            moving = np.flatnonzero(np.ptp(samples, axis=0) > 0)
            points = np.ascontiguousarray(samples[None][:, :, moving])
            v, a, j = limits[:, moving]
            estimate = sampled_path_durations(points, v, a, j, window_s, ROUNDS, TOLERANCE, SECOND_SHARE)[0]
            assert estimate == pytest.approx(timed, rel=tolerance)
    still = np.zeros((1, 10, 2))
    ones = np.ones(2)
    assert (
        sampled_path_durations(still, ones, ones, ones, window_s, ROUNDS, TOLERANCE, SECOND_SHARE)[0] == 0.0
    )
