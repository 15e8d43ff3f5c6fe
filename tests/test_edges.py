"""Edge checks (the coarse-to-fine free fraction is the exhaustive one), straightened joints."""

from __future__ import annotations

import itertools
import math

import numpy as np

from planning.search.edges import (
    COARSE_STRIDE,
    HEAD,
    WHOLE_BELOW,
    Edges,
    path_time,
    straighten_joints,
)


def discs(q: np.ndarray) -> np.ndarray:
    """Valid outside three discs of the unit square."""
    centres = np.array([[0.3, 0.3], [0.7, 0.6], [0.4, 0.8]])
    return np.asarray((np.linalg.norm(q[:, None] - centres, axis=2) > 0.12).all(axis=1))


def exhaustive(a: np.ndarray, b: np.ndarray, weights: np.ndarray, resolution_m: float) -> float:
    count = max(1, math.ceil(float(np.abs(b - a) @ weights) / resolution_m))
    fractions = np.arange(1, count + 1) / count
    ok = discs(a + fractions[:, None] * (b - a))
    first_bad = count if ok.all() else int(np.argmin(ok))
    return 1.0 if first_bad == count else 0.0 if first_bad == 0 else float(fractions[first_bad - 1])


def test_the_free_fractions_are_those_of_checking_every_configuration() -> None:
    rng = np.random.default_rng(3)
    weights = np.array([1.0, 2.0])
    edges = Edges(discs, weights, 0.002)  # long edges: hundreds of configurations, checked coarse to fine
    pairs = [(a, b) for a, b in rng.uniform(0, 1, (200, 2, 2)) if discs(a[None])[0]]
    found = [edges.free_fraction(a, b) for a, b in pairs]
    assert found == [exhaustive(a, b, weights, 0.002) for a, b in pairs]
    assert 0 < sum(f < 1 for f in found) < len(found)  # some edges blocked, some free
    every = sum(max(1, math.ceil(float(np.abs(b - a) @ weights) / 0.002)) for a, b in pairs)
    assert edges.checks < every  # blocked edges were not checked past their obstacle


def test_an_edge_blocked_at_once_is_known_from_its_coarse_pass() -> None:
    weights = np.array([1.0, 2.0])
    edges = Edges(discs, weights, 0.002)
    a, b = np.array([0.3, 0.1795]), np.array([0.3, 0.9])  # half a step from the first disc, across it
    count = math.ceil(float(np.abs(b - a) @ weights) / 0.002)
    assert discs(a[None])[0] and count >= WHOLE_BELOW
    assert edges.free_fraction(a, b) == 0.0
    coarse = set(range(HEAD)) | set(range(COARSE_STRIDE - 1, count, COARSE_STRIDE)) | {count - 1}
    assert edges.checks == len(coarse)  # the coarse pass alone: nothing past the first invalid one


def test_a_check_that_stops_at_the_first_invalid_configuration_gives_the_same_fractions() -> None:
    """The validity's contract: exact up to the first invalid configuration, anything after it."""
    noise = np.random.default_rng(5)

    def stops_early(q: np.ndarray) -> np.ndarray:
        ok = discs(q)
        if not ok.all():
            after = int(np.argmin(ok)) + 1
            ok[after:] = noise.uniform(size=len(q) - after) < 0.5
        return ok

    rng = np.random.default_rng(4)
    weights = np.array([1.0, 2.0])
    pairs = [(a, b) for a, b in rng.uniform(0, 1, (200, 2, 2)) if discs(a[None])[0]]
    for resolution_m in (0.002, 0.03):  # coarse to fine, and whole edges
        exact, early = Edges(discs, weights, resolution_m), Edges(stops_early, weights, resolution_m)
        found = [early.free_fraction(a, b) for a, b in pairs]
        assert found == [exact.free_fraction(a, b) for a, b in pairs]
        assert 0 < sum(f < 1 for f in found) < len(found)


def everywhere(q: np.ndarray) -> np.ndarray:
    return np.ones(len(q), dtype=bool)


def test_a_wandering_slow_joint_is_straightened_until_the_path_is_the_straight_line() -> None:
    """Joints 0 and 1 go straight; the slow joint 2 wanders: straightened, the path is the line."""
    speeds = np.array([1.0, 1.0, 0.1])
    path = np.array([[0.0, 0.0, 0.0], [0.25, 0.5, 0.8], [0.5, 1.0, -0.5], [0.75, 1.5, 0.6], [1.0, 2.0, 0.1]])
    edges = Edges(everywhere, np.ones(3), 0.01)
    straightened = straighten_joints(path, edges, speeds, np.random.default_rng(0), 100)
    np.testing.assert_array_equal(straightened[:, :2], path[:, :2])  # the other joints keep their values
    np.testing.assert_array_equal(straightened[[0, -1]], path[[0, -1]])
    direct_s = float(np.max(np.abs(path[-1] - path[0]) / speeds))
    assert path_time(path, speeds) > 3 * direct_s
    assert math.isclose(path_time(straightened, speeds), direct_s, rel_tol=1e-9)
    assert np.all(np.diff(straightened[:, 2]) >= 0.0)  # monotone, at the pace of the others


def test_a_straightened_joint_that_would_cross_an_obstacle_is_not_taken() -> None:
    """Joint 1 lifts over a block that its straight move would cross: the detour stays."""

    def beside_block(q: np.ndarray) -> np.ndarray:
        return np.asarray(~((np.abs(q[:, 0] - 0.5) < 0.1) & (q[:, 1] < 0.5)))

    path = np.array([[0.0, 0.0], [0.5, 0.8], [1.0, 0.0]])
    edges = Edges(beside_block, np.ones(2), 0.005)
    straightened = straighten_joints(path, edges, np.ones(2), np.random.default_rng(1), 20)
    np.testing.assert_array_equal(straightened, path)
    assert edges.checks > 0  # it was tried, and refused by the validity check


def test_a_straightened_joint_that_saves_no_time_costs_no_check() -> None:
    """The wandering joint is fast; the slow one sets every edge's time: nothing to gain, nothing checked."""
    path = np.array([[0.0, 0.0], [0.5, 0.3], [1.0, -0.2], [1.5, 0.0]])
    edges = Edges(everywhere, np.ones(2), 0.01)
    straightened = straighten_joints(path, edges, np.array([0.1, 10.0]), np.random.default_rng(2), 50)
    np.testing.assert_array_equal(straightened, path)
    assert edges.checks == 0


def test_a_chain_is_free_exactly_when_every_edge_is() -> None:
    rng = np.random.default_rng(6)
    weights = np.array([1.0, 2.0])
    for _ in range(100):
        chain = rng.uniform(0, 1, (4, 2))
        if not discs(chain[:1])[0]:
            continue
        every = all(exhaustive(a, b, weights, 0.002) == 1.0 for a, b in itertools.pairwise(chain))
        assert Edges(discs, weights, 0.002).chain_free(chain) == every


def test_an_edge_from_an_unchecked_point_is_free_only_when_that_point_is_too() -> None:
    """``free_between`` checks the edge's start as well: a shortcut starts at a point of another
    edge that no check has seen. Outside the first disc every such answer is ``free_fraction``'s."""
    rng = np.random.default_rng(7)
    weights = np.array([1.0, 2.0])
    edges = Edges(discs, weights, 0.002)
    inside, beyond = np.array([0.3, 0.1805]), np.array([0.3, 0.05])  # just in the first disc; below it
    assert not discs(inside[None])[0] and edges.free_fraction(inside, beyond) == 1.0
    assert not edges.free_between(inside, beyond)
    pairs = [(a, b) for a, b in rng.uniform(0, 1, (200, 2, 2)) if discs(a[None])[0]]
    assert [edges.free_between(a, b) for a, b in pairs] == [
        edges.free_fraction(a, b) == 1.0 for a, b in pairs
    ]
