"""The coarse-first fine grid of the certified checks: the whole grid's minima, from a fraction of it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import cpr_kin as ck
import cpr_kin.certified.coarse_first as coarse_first_module
from cpr_kin.certified.coarse_first import STRIDE, GridSampler, coarse_first
from cpr_kin.certified.self_curve import check_self_curve
from cpr_kin.collision.decisive import certified, undecided, with_neighbours
from cpr_kin.model.packages import example_robot

from .conftest import PAPER_GOAL_TCP, PAPER_START_TCP

COUNT = 40_001
LIPSCHITZ = 1.0  # of the clearance below [m per unit of t]
LOOSENESS = 0.03  # of its cheap lower bounds [m]


def clearance(t: np.ndarray) -> np.ndarray:
    """Two columns over t in [0, 1], each changing at most ``LIPSCHITZ`` per unit of t [m]."""
    first = 0.05 + 0.3 * (t - 0.37) ** 2 + 0.002 * np.sin(40.0 * t)
    second = 0.08 + 0.2 * np.abs(t - 0.81) + 0.01 * np.cos(25.0 * t)
    return np.stack([first, second], axis=1)


class Sampled:
    """A sampler of :func:`clearance` on ``count`` samples, as a check samples a curve.

    Each sample has a cheap lower bound, ``LOOSENESS`` below the clearance or less; the exact
    value is computed ("coal") only where it decides the minima (the checks' own rule,
    :func:`~cpr_kin.collision.decisive.undecided`), and counted.
    """

    def __init__(self, count: int = COUNT, slowing: float = 0.0) -> None:
        self.times = np.linspace(0.0, 1.0, count)
        self.evaluated = 0
        self.slowing = slowing  # the curve slows to (1 - slowing) of its speed about the first minimum

    def bounds(self, rows: np.ndarray) -> np.ndarray:
        t = self.times[rows]
        return np.asarray(clearance(t) - LOOSENESS * (1.0 + np.sin(7.0 * t)[:, None]) / 2)

    def exact(self, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        self.evaluated += len(rows)
        return clearance(self.times[rows]), np.zeros((len(rows), 2), dtype=np.int64)

    def decide(self, rows: np.ndarray, slack: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        bounds = self.bounds(rows)
        values, known = bounds.copy(), np.zeros(bounds.shape, dtype=bool)
        reach = np.r_[0.0, np.cumsum(slack)]
        while (needed := undecided(values, known, slack)).any():
            for g in range(2):
                at = np.flatnonzero(needed[:, g])
                values[at, g] = self.exact(rows[at])[0][:, g]
                known[at, g] = True
                values[:, g] = with_neighbours(values[:, g], known[:, g], bounds[:, g], reach)
        return values, np.where(known, 0, -1)

    def slack(self, rows: np.ndarray) -> np.ndarray:
        t = self.times[rows]
        speed = 1.0 - self.slowing * np.exp(-(((t[:-1] + t[1:]) / 2 - 0.37) ** 2) / 0.01)
        return np.asarray(LIPSCHITZ * speed * np.diff(t))

    def sampler(self) -> GridSampler:
        step = float(np.max(np.diff(self.times)))
        return GridSampler(len(self.times), self.decide, self.exact, self.slack, LIPSCHITZ * step)

    def whole(self) -> tuple[np.ndarray, np.ndarray]:
        """The whole grid decided at once: its values and slack."""
        every = np.arange(len(self.times))
        slack = self.slack(every)
        return self.decide(every, slack)[0], slack


@pytest.mark.parametrize("slowing", [0.0, 0.9])
def test_the_minima_are_the_whole_grids_from_a_fraction_of_its_samples(slowing: float) -> None:
    # slowing: a curve slower about its closest approach (a grasp) gives its intervals there less slack
    sampled, whole = Sampled(slowing=slowing), Sampled(slowing=slowing)
    grid = coarse_first(sampled.sampler())
    values, slack = whole.whole()
    np.testing.assert_array_equal(
        certified(grid.values, grid.slack).min(axis=0), certified(values, slack).min(axis=0)
    )
    np.testing.assert_array_equal(grid.values.min(axis=0), values.min(axis=0))
    np.testing.assert_array_equal(grid.values.argmin(axis=0), values.argmin(axis=0))
    np.testing.assert_array_equal(grid.values.min(axis=0), clearance(sampled.times).min(axis=0))  # exact
    assert sampled.evaluated < whole.evaluated / 3  # exact values: the coarse ones, and about the minima


def test_every_value_and_interval_bound_holds() -> None:
    # what the grid holds where it was not sampled finely is a lower bound, at each sample and
    # over each interval (dense samples of the clearance between them)
    sampled = Sampled()
    grid = coarse_first(sampled.sampler())
    assert np.all(grid.values <= clearance(sampled.times) + 1e-15)
    dense = np.linspace(0.0, 1.0, 8 * (COUNT - 1) + 1)
    lowest_between = clearance(dense)[:-1].reshape(COUNT - 1, 8, 2).min(axis=1)
    assert np.all(certified(grid.values, grid.slack) <= lowest_between + 1e-15)
    assert np.all(grid.slack >= sampled.slack(np.arange(COUNT)) - 1e-18)  # a bound on each interval's motion


def test_minima_found_elsewhere_leave_the_grid_coarse() -> None:
    # another pair's minima below anything this one can reach: nothing is sampled finely
    sampled = Sampled()
    grid = coarse_first(sampled.sampler(), ceilings=(0.0, 0.0))
    assert sampled.evaluated < len(np.unique(np.r_[np.arange(0, COUNT, STRIDE), COUNT - 1]))
    assert certified(grid.values, grid.slack).min() >= 0.0


def test_a_small_grid_is_decided_whole_in_one_call() -> None:
    sampled, calls = Sampled(count=coarse_first_module.FROM_SAMPLES - 1), []
    sampler = sampled.sampler()

    def decide(rows: np.ndarray, slack: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        calls.append(rows)
        return sampler.decide(rows, slack)

    grid = coarse_first(dataclasses.replace(sampler, decide=decide))
    assert len(calls) == 1 and len(calls[0]) == len(sampled.times)
    np.testing.assert_array_equal(grid.values, Sampled(count=len(sampled.times)).whole()[0])


def whole_and_coarse_first(
    monkeypatch: pytest.MonkeyPatch, check: object, *args: object
) -> tuple[object, object]:
    with monkeypatch.context() as patch:
        patch.setattr(coarse_first_module, "FROM_SAMPLES", 10**12)
        whole = check(*args)  # type: ignore[operator]
    return whole, check(*args)  # type: ignore[operator]


@pytest.mark.parametrize("lift_m", [0.0, 0.25])
def test_a_fine_obstacle_check_decides_as_the_whole_grid(
    monkeypatch: pytest.MonkeyPatch, robot: ck.Robot, paper_world: ck.CollisionWorld, lift_m: float
) -> None:
    # the paper's swing past the crate (refused), and lifted clear of it (accepted), at 0.1 mm
    start, goal = ck.tcp_ik(robot, PAPER_START_TCP), ck.tcp_ik(robot, PAPER_GOAL_TCP)
    start[1] = goal[1] = min(start[1] + lift_m, robot.limits.upper[1])
    whole, fine = whole_and_coarse_first(
        monkeypatch, ck.check_segment, paper_world, start, goal, 0.05, 0.0001
    )
    assert isinstance(whole, ck.CurveCheck) and isinstance(fine, ck.CurveCheck)
    assert len(fine.times) == len(whole.times) >= coarse_first_module.FROM_SAMPLES
    assert fine.accepted == whole.accepted == (lift_m > 0)
    assert fine.certified_min_m == pytest.approx(whole.certified_min_m, abs=1e-6)  # coal's error
    assert fine.sampled_min_m == pytest.approx(whole.sampled_min_m, abs=1e-6)
    assert (fine.worst_pair, fine.worst_group, fine.violating_groups) == (
        whole.worst_pair,
        whole.worst_group,
        whole.violating_groups,
    )


def test_a_fine_self_check_decides_as_the_whole_grid(monkeypatch: pytest.MonkeyPatch) -> None:
    panda = ck.load_robot(example_robot("panda"))
    collision = ck.CollisionWorld(panda, []).self_collision
    assert collision is not None
    rng = np.random.default_rng(5)
    for _ in range(3):
        a, b = rng.uniform(panda.limits.lower, panda.limits.upper, (2, panda.nq))

        def line(t: np.ndarray, a: np.ndarray = a, b: np.ndarray = b) -> np.ndarray:
            return np.asarray(a + np.asarray(t)[:, None] * (b - a))

        args = (collision, line, (0.0, 1.0), np.abs(b - a), 0.0, 0.0001)
        whole, fine = whole_and_coarse_first(monkeypatch, check_self_curve, *args)
        assert fine.accepted == whole.accepted  # type: ignore[attr-defined]
        assert fine.certified_min_m == pytest.approx(whole.certified_min_m, abs=1e-6)  # type: ignore[attr-defined]
        assert fine.worst_pair == whole.worst_pair  # type: ignore[attr-defined]
        assert fine.computed <= whole.computed  # type: ignore[attr-defined]
