from __future__ import annotations

from itertools import pairwise
from unittest import mock

import numpy as np

import cpr_kin as ck
from planning.curves import velocity_caps
from planning.curves.arc_length import ArcLengthPath, arc_length_path
from planning.curves.path_timing import SECOND_SHARE
from planning.curves.phase_plane import profile_time
from planning.curves.trajectory import Trajectory
from planning.curves.velocity_caps import (
    CappedMotion,
    capped_motion,
    capped_profile,
    duration_lower_bound,
    fastest_motion,
)

from .conftest import LIFT, PAPER_GOAL_TCP, PAPER_START_TCP, limits_of, spline_path


def every_cap(grid: ArcLengthPath, limits: np.ndarray, second: float) -> CappedMotion:
    """The cap search with no early stop: every cap of the grid, as first written, then the local caps."""
    tried = {1.0: velocity_caps.capped_motion(grid, limits, second, 1.0)}
    peak = tried[1.0].peak
    for share in (factor * peak for factor in velocity_caps.FACTORS):
        tried[share] = velocity_caps.capped_motion(grid, limits, second, share)
    for high, low in pairwise(sorted(tried, reverse=True)):
        if tried[high].widened and not tried[low].widened:
            velocity_caps.bisect_widening(grid, limits, second, tried, high, low, peak)
            break
    share = min(tried, key=lambda share: (tried[share].duration_s, -share))
    best = tried[share]
    for factor in velocity_caps.RAMP_FACTORS:
        found = velocity_caps.capped_motion(grid, limits, second, share, factor * best.window_s)
        if found.duration_s < best.duration_s:
            best = found
    if tried[1.0].widened:
        local = velocity_caps.locally_capped(grid, limits, second, tried[1.0])
        if local.duration_s < best.duration_s:
            best = local
    return best


def straight_and_lifted(lines: list[tuple[np.ndarray, np.ndarray]]) -> list[Trajectory]:
    """Splines along each line, and through a lift above each end: the timings' test paths."""
    paths = [spline_path(np.linspace(q0, q1, 5)) for q0, q1 in lines]
    return paths + [
        spline_path(np.array([q0, q0 + LIFT, q1 + LIFT * [-1, 1, 1, 1, 1], q1])) for q0, q1 in lines
    ]


def test_the_cap_search_stops_early_with_what_every_cap_gives(
    robot: ck.Robot, lines: list[tuple[np.ndarray, np.ndarray]]
) -> None:
    limits = np.stack(limits_of(robot))
    paths = straight_and_lifted(lines)
    calls = {"stopped": 0, "every": 0}
    for path in paths:
        for factor in (1.0, 0.35):  # the planner's limits and its narrowed ones
            narrowed = limits * np.array([[1.0], [factor], [1.0]])
            grid = arc_length_path(path, narrowed[0])
            for name, search in (("stopped", fastest_motion), ("every", every_cap)):
                with mock.patch.object(velocity_caps, "capped_motion", wraps=capped_motion) as spy:
                    found = search(grid, narrowed, SECOND_SHARE)
                calls[name] += spy.call_count
                if name == "stopped":
                    stopped = found
            assert stopped.duration_s == found.duration_s and stopped.step_s == found.step_s
            np.testing.assert_array_equal(stopped.motion, found.motion)
    assert calls["stopped"] < 0.7 * calls["every"]


def test_a_lower_velocity_cap_never_shortens_the_phase_plane_time(robot: ck.Robot) -> None:
    """What the early stop of the cap search rests on: the profile's time grows as its cap falls."""
    limits = np.stack(limits_of(robot))
    q0, q1 = ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP)
    for nodes in (np.linspace(q0, q1, 5), np.array([q0, q0 + LIFT, q1 + LIFT * [-1, 1, 1, 1, 1], q1])):
        grid = arc_length_path(spline_path(nodes), limits[0])
        times = [
            profile_time(capped_profile(grid, limits, share), grid.ds) for share in np.linspace(1, 0.1, 60)
        ]
        assert np.all(np.diff(times) >= -1e-12 * times[0])


def test_the_duration_lower_bound_is_below_every_caps_motion(
    robot: ck.Robot, lines: list[tuple[np.ndarray, np.ndarray]]
) -> None:
    """What skipping a cap rests on: no cap's averaged, scaled motion is shorter than its bound."""
    limits = np.stack(limits_of(robot))
    paths = straight_and_lifted(lines)
    gaps = []
    for path in paths:
        grid = arc_length_path(path, limits[0])
        for share in (1.0, 0.8, 0.5, 0.3):
            for ramp_s in (np.inf, 0.05):
                x = capped_profile(grid, limits, share, ramp_s)
                bound = duration_lower_bound(grid, limits, SECOND_SHARE, x)
                found = capped_motion(grid, limits, SECOND_SHARE, share, ramp_s, profile=x)
                gaps.append((found.duration_s - bound) / found.duration_s)
    assert min(gaps) >= 0.0
    assert np.median(gaps) < 0.02  # and tight where no window widens and nothing is rescaled
