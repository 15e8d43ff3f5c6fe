"""Torque limits in the timing: phase-plane rows with an offset, and the exact uniform time scale."""

from __future__ import annotations

import numpy as np
import pytest

import cpr_kin as ck
from planning.curves.jerk_window import jerk_limited_duration, profile_window, sampled_path_durations
from planning.curves.path_timing import SECOND_SHARE, time_path
from planning.curves.phase_plane import phase_plane_profile, sampled_derivatives
from planning.curves.spline import SepticSplineSolver, uniform_knots
from planning.curves.torque_estimate import (
    TERM_STRIDE,
    path_picks,
    sampled_torque_durations,
    torque_limited_duration,
)
from planning.curves.torque_limits import (
    HEADROOM,
    TorqueRows,
    local_peaks,
    phase_plane_rows,
    torque_time_scale,
)
from planning.curves.trajectory import Trajectory
from planning.curves.velocity_caps import ROUNDS, TOLERANCE
from planning.pipeline.scene import DEFAULT_SPLINE
from planning.pipeline.torques import search_torque, torque_profile


def polynomial_path(seed: int, joints: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    u = np.linspace(0.0, 1.0, 300)
    coefficients = rng.normal(size=(4, joints))
    d1 = np.column_stack([np.polyval(np.polyder(c[::-1]), u) for c in coefficients.T])
    d2 = np.column_stack([np.polyval(np.polyder(c[::-1], 2), u) for c in coefficients.T])
    return u, d1, d2


@pytest.mark.parametrize("seed", range(6))
def test_rows_with_an_offset_are_kept_at_every_grid_point(seed: int) -> None:
    u, d1, d2 = polynomial_path(seed)
    rng = np.random.default_rng(100 + seed)
    a = rng.uniform(1.0, 3.0, 3)
    offset = rng.uniform(-0.6, 0.6, (1, 3)) * a * np.cos(3 * u)[:, None]  # "gravity" within the limits
    du = np.diff(u)
    x = phase_plane_profile(d1, d2, du, np.full(3, np.inf), a, offset)
    push = np.diff(x) / (2.0 * du)  # u'' on each step, applied from its first point
    value = d1[:-1] * push[:, None] + d2[:-1] * x[:-1, None] + offset[:-1]
    assert np.max(np.abs(value) / a) <= 1.0 + 1e-6
    assert x[0] == x[-1] == 0.0 and x.max() > 0.0


def test_a_redundant_row_changes_nothing() -> None:
    u, d1, d2 = polynomial_path(7)
    v, a, du = np.array([1.0, 1.5, 2.0]), np.array([2.0, 1.0, 3.0]), np.diff(u)
    alone = phase_plane_profile(d1, d2, du, v, a, np.zeros_like(d1))
    # a "torque" row that is joint 1's acceleration times 4, limited to 4 times its limit
    rows = phase_plane_profile(
        np.hstack([d1, 4 * d1[:, 1:2]]),
        np.hstack([d2, 4 * d2[:, 1:2]]),
        du,
        np.append(v, np.inf),
        np.append(a, 4 * a[1]),
        np.zeros((len(u), 4)),
    )
    assert rows == pytest.approx(alone, rel=1e-9, abs=1e-12)


@pytest.fixture(scope="module")
def robot() -> ck.Robot:
    return ck.load_cpr()


@pytest.fixture(scope="module")
def path(robot: ck.Robot) -> Trajectory:
    nodes = np.array([[0.0, 0.1, 0.1, 0.0, 0.0], [0.8, 0.45, 0.3, 0.5, 0.2], [1.5, 0.5, 0.4, 1.0, 0.5]])
    solver = SepticSplineSolver(uniform_knots(2, 2.0), DEFAULT_SPLINE)
    return solver.solve(nodes).trajectory


def test_the_uniform_scale_meets_the_torque_limit_exactly(robot: ck.Robot, path: Trajectory) -> None:
    dynamics = ck.robot_dynamics(robot, ck.Payload(12.0, (0.0, 0.0, 0.05)))
    fast = path.time_scaled(0.5)
    scale = torque_time_scale(fast, dynamics)
    assert scale > 1.0  # too fast for the payload
    scaled = fast.time_scaled(scale)
    usage = torque_profile(dynamics, scaled, step_s=scaled.duration / 4000).utilisation.max()
    assert usage == pytest.approx(1.0 - HEADROOM, abs=2e-4)


@pytest.mark.parametrize(("mass_kg", "speed_up"), [(12.0, 0.5), (15.0, 0.35), (4.0, 0.2)])
def test_the_uniform_scale_misses_no_peak_between_its_samples(
    robot: ck.Robot, path: Trajectory, mass_kg: float, speed_up: float
) -> None:
    """The oracle: the scaled trajectory's torques every 40 us reach the limit less HEADROOM, to 1e-7."""
    dynamics = ck.robot_dynamics(robot, ck.Payload(mass_kg, (0.0, 0.0, 0.05)))
    fast = path.time_scaled(speed_up)
    scaled = fast.time_scaled(torque_time_scale(fast, dynamics))
    usage = torque_profile(dynamics, scaled, step_s=4e-5).utilisation.max()
    assert usage == pytest.approx(1.0 - HEADROOM, abs=1e-7)


def test_local_peaks_are_the_maxima_above_the_floor_ends_and_plateaus_included() -> None:
    values = np.array([3.0, 1.0, 2.0, 2.0, 0.5, 4.0, 1.0, 5.0])
    assert np.flatnonzero(local_peaks(values, floor=0.0)).tolist() == [0, 2, 3, 5, 7]
    assert np.flatnonzero(local_peaks(values, floor=3.5)).tolist() == [5, 7]
    assert not local_peaks(np.linspace(0.0, 1.0, 9)[::-1], floor=2.0).any()


@pytest.mark.parametrize("mass_kg", [0.0, 8.0, 15.0])
def test_the_fastest_timing_keeps_the_torques_and_uses_them_when_they_bind(
    robot: ck.Robot, path: Trajectory, mass_kg: float
) -> None:
    limits = robot.limits
    dynamics = ck.robot_dynamics(robot, ck.Payload(mass_kg, (0.0, 0.0, 0.05)))
    kinematic = time_path(path, limits.velocity, limits.acceleration, limits.jerk)
    timed = time_path(path, limits.velocity, limits.acceleration, limits.jerk, torque=dynamics)
    usage = torque_profile(dynamics, timed).peak_utilisation
    assert usage.max() <= 1.0
    for r, limit in enumerate((limits.velocity, limits.acceleration, limits.jerk), start=1):
        assert np.max(timed.extrema(r).peak / limit) <= 1.0 + 1e-9
    if torque_profile(dynamics, kinematic).peak_utilisation.max() <= 1.0:  # torque does not bind
        assert timed.duration == pytest.approx(kinematic.duration, rel=1e-12)
    else:  # it binds: no time left on the table, and slower than the kinematic timing
        assert usage.max() == pytest.approx(1.0 - HEADROOM, abs=2e-3) and timed.duration > kinematic.duration


def limits_of(kinematic: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return kinematic[0], kinematic[1], kinematic[2]


def test_the_search_estimate_keeps_the_torques_where_they_bind(robot: ck.Robot, path: Trajectory) -> None:
    limits = robot.limits
    kinematic = np.stack([limits.velocity, limits.acceleration, limits.jerk])
    window = float(np.max(limits.acceleration / limits.jerk))
    samples = path(np.linspace(path.knots[0], path.knots[-1], 64))[None]
    fitted = np.arange(robot.nq)
    plain = sampled_path_durations(samples, *limits_of(kinematic), window, ROUNDS, TOLERANCE, SECOND_SHARE)
    light = ck.robot_dynamics(robot, ck.Payload(2.0, (0.0, 0.0, 0.05)))
    assert sampled_torque_durations(samples, fitted, kinematic, light, window, SECOND_SHARE) == pytest.approx(
        plain, rel=1e-12
    )
    heavy = ck.robot_dynamics(robot, ck.Payload(15.0, (0.0, 0.0, 0.05)))
    estimate = sampled_torque_durations(samples, fitted, kinematic, heavy, window, SECOND_SHARE)[0]
    timed = time_path(path, limits.velocity, limits.acceleration, limits.jerk, torque=heavy).duration
    assert estimate > plain[0] and estimate == pytest.approx(timed, rel=0.1)


def test_the_search_estimate_of_many_paths_is_each_paths_own(robot: ck.Robot, path: Trajectory) -> None:
    # one batched RNEA for every path's rows: each path's estimate as if it were alone
    limits = robot.limits
    kinematic = np.stack([limits.velocity, limits.acceleration, limits.jerk])
    window = float(np.max(limits.acceleration / limits.jerk))
    along = path(np.linspace(path.knots[0], path.knots[-1], 64))
    still = np.repeat(along[:1], 64, axis=0)  # a path that does not move: no estimate
    samples = np.stack([along, still, along[::-1], along * 0.5, along])
    heavy = ck.robot_dynamics(robot, ck.Payload(15.0, (0.0, 0.0, 0.05)))
    fitted = np.arange(robot.nq)
    together = sampled_torque_durations(samples, fitted, kinematic, heavy, window, SECOND_SHARE)
    alone = [
        sampled_torque_durations(one[None], fitted, kinematic, heavy, window, SECOND_SHARE)[0]
        for one in samples
    ]
    assert together.tolist() == alone and together[1] == 0.0 and len(set(together.tolist())) >= 3


def test_the_estimate_of_a_few_fitted_joints_is_theirs(robot: ck.Robot, path: Trajectory) -> None:
    """Fitted joints a subset: without binding torques, their own estimate; where gravity alone
    exceeds a limit (a payload no joint holds), the estimate without torques too."""
    limits = robot.limits
    fitted = np.array([0, 2, 3])
    kinematic = np.stack([limits.velocity, limits.acceleration, limits.jerk])[:, fitted]
    window = float(np.max(limits.acceleration / limits.jerk))
    samples = path(np.linspace(path.knots[0], path.knots[-1], 64))[None]
    points = np.ascontiguousarray(samples[:, :, fitted])
    plain = sampled_path_durations(points, *limits_of(kinematic), window, ROUNDS, TOLERANCE, SECOND_SHARE)
    light = ck.robot_dynamics(robot, ck.Payload(2.0, (0.0, 0.0, 0.05)))
    assert sampled_torque_durations(samples, fitted, kinematic, light, window, SECOND_SHARE).tolist() == [
        pytest.approx(plain[0], rel=1e-12)
    ]
    crushing = ck.robot_dynamics(robot, ck.Payload(1000.0, (0.0, 0.0, 0.05)))
    assert np.any(
        np.abs(crushing.path_terms(samples[0], 0 * samples[0], 0 * samples[0])[2]) > crushing.effort
    )
    assert sampled_torque_durations(samples, fitted, kinematic, crushing, window, SECOND_SHARE).tolist() == (
        plain.tolist()
    )


@pytest.mark.parametrize("kept", range(2, 14))
def test_the_torques_are_computed_at_every_strideth_sample_and_the_last(kept: int) -> None:
    expected = sorted({*range(0, kept, TERM_STRIDE), kept - 1})
    assert path_picks(kept, TERM_STRIDE).tolist() == expected


def test_the_compiled_estimate_of_a_path_is_the_rows_profile_and_window_composed(
    robot: ck.Robot, path: Trajectory
) -> None:
    """torque_limited_duration against its pieces in Python: the interpolated torque rows of
    phase_plane_rows, the phase-plane profile, its jerk window and duration."""
    limits = robot.limits
    kinematic = np.stack([limits.velocity, limits.acceleration, limits.jerk])
    window = float(np.max(limits.acceleration / limits.jerk))
    points = path(np.linspace(path.knots[0], path.knots[-1], 64))
    heavy = ck.robot_dynamics(robot, ck.Payload(15.0, (0.0, 0.0, 0.05)))
    steps, d1, d2 = sampled_derivatives(points, limits.velocity)
    pick = np.append(np.arange(0, len(d1), 4), len(d1) - 1)
    terms = np.stack(heavy.path_terms(points[pick], d1[pick], d2[pick]))
    bound = heavy.effort * (1.0 - HEADROOM)
    where = np.arange(len(d1))
    right = np.clip(np.searchsorted(pick, where), 1, len(pick) - 1)
    share = ((where - pick[right - 1]) / (pick[right] - pick[right - 1]))[None, :, None]
    slope, curve, offset = terms[:, right - 1] * (1.0 - share) + terms[:, right] * share
    torque_rows = TorqueRows(slope, curve, offset, bound)
    rows = phase_plane_rows(d1, d2, limits.velocity, limits.acceleration, torque_rows)
    x = phase_plane_profile(rows[0], rows[1], steps, rows[2], rows[3], rows[4])
    times, used, usage = profile_window(x, steps, d1, limits.jerk, window, ROUNDS, TOLERANCE, SECOND_SHARE)
    composed = jerk_limited_duration(times, used, usage, SECOND_SHARE)
    compiled = torque_limited_duration(
        steps, d1, d2, pick, terms, bound, kinematic, window, ROUNDS, TOLERANCE, SECOND_SHARE
    )
    assert compiled == composed
    plain = sampled_path_durations(
        points[None], *limits_of(kinematic), window, ROUNDS, TOLERANCE, SECOND_SHARE
    )
    assert compiled > plain[0]  # the payload's torques bind


def test_the_search_keeps_torques_only_when_they_bind_on_the_straight_path(robot: ck.Robot) -> None:
    start, goal = np.array([0.0, 0.1, 0.1, 0.0, 0.0]), np.array([1.5, 0.5, 0.4, 1.0, 0.5])
    light = ck.robot_dynamics(robot, ck.Payload(5.0))
    heavy = ck.robot_dynamics(robot, ck.Payload(15.0))
    assert search_torque(robot, light, start, goal) is None  # the CPR's torques stay below half
    assert search_torque(robot, heavy, start, goal) is heavy
    assert search_torque(robot, heavy, start, start) is None
