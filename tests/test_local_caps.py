from __future__ import annotations

import numpy as np
from scipy.ndimage import minimum_filter1d

import cpr_kin as ck
from planning.curves import velocity_caps
from planning.curves.arc_length import arc_length_path
from planning.curves.local_caps import entering
from planning.curves.moving_average import scaled_duration
from planning.curves.path_timing import SECOND_SHARE, time_path
from planning.curves.trajectory import Trajectory

from .conftest import limits_of, spline_path


def curved_paths(robot: ck.Robot, count: int) -> list[Trajectory]:
    """Seeded paths through two random configurations between two others: bends of every kind."""
    rng = np.random.default_rng(11)
    lower, upper = robot.limits.lower, robot.limits.upper
    return [spline_path(rng.uniform(lower, upper, (4, len(lower)))) for _ in range(count)]


def test_each_input_takes_the_least_cut_of_the_outputs_it_enters() -> None:
    rng = np.random.default_rng(3)
    for reach in (1, 4, 7):
        cut = rng.uniform(0.5, 1.0, (40 + reach, 3))
        spread = entering(cut, reach)
        for i in range(40):  # input i enters the outputs i .. i + reach (brute force)
            np.testing.assert_array_equal(spread[i], cut[i : i + reach + 1].min(axis=0))


def test_the_running_minimum_is_scipys_on_every_size() -> None:
    # SciPy's minimum_filter1d, an independent oracle (the windows ahead, clamped at the end)
    rng = np.random.default_rng(5)
    for rows in (1, 2, 3, 17, 200, 1001):
        for reach in (0, 1, 2, 7, 8, 113, 300, 2000):
            cut = rng.uniform(0.5, 1.0, (rows, 3))
            expected = minimum_filter1d(cut, reach + 1, axis=0, origin=-((reach + 1) // 2), mode="nearest")
            np.testing.assert_array_equal(entering(cut, reach), expected)


def test_the_local_caps_win_where_the_window_widens_and_stay_within_the_limits(robot: ck.Robot) -> None:
    limits = np.stack(limits_of(robot))
    won = 0
    for path in curved_paths(robot, 12):
        grid = arc_length_path(path, limits[0])
        uncapped = velocity_caps.capped_motion(grid, limits, SECOND_SHARE, 1.0)
        if not uncapped.widened:
            continue
        local = velocity_caps.locally_capped(grid, limits, SECOND_SHARE, uncapped)
        assert local.duration_s == scaled_duration(local.motion, local.step_s, *limits)
        np.testing.assert_allclose(local.motion[0, [0, -1]], path(path.knots[[0, -1]]), atol=1e-9)
        fastest = velocity_caps.fastest_motion(grid, limits, SECOND_SHARE)
        assert fastest.duration_s <= local.duration_s
        if fastest.duration_s == local.duration_s and local.duration_s < uncapped.duration_s:
            won += 1
            timed = time_path(path, *limits)
            peaks = [np.max(timed.extrema(r).peak / limits[r - 1]) for r in (1, 2, 3)]
            assert max(peaks) <= 1 + 1e-9 and max(peaks) >= 1 - 1e-9
            assert timed.duration <= 1.02 * fastest.duration_s
    assert won >= 2
