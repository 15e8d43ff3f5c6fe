"""RRT-Connect on a 2-D maze whose free space is known exactly, and the waypoints along a path."""

from __future__ import annotations

import dataclasses
import itertools
import math

import numpy as np
import pytest
from numpy.typing import NDArray

from planning.errors import PlanningError
from planning.search.edges import ScreenedValidity, path_time, screen_of
from planning.search.rrt_connect import Relaxation, RrtPath, rrt_connect
from planning.search.rrt_settings import RrtSettings
from planning.search.rrt_trees import Sampler, Tree
from planning.search.waypoints import waypoints_along

WEIGHTS = np.ones(2)
LOWER, UPPER = np.zeros(2), np.ones(2)


def wall_with_slot(q: NDArray[np.float64], shrink: float = 0.0) -> NDArray[np.bool_]:
    """Free unless in the wall ``0.45 < x < 0.55``, except for the slot ``0.45 < y < 0.5``.

    ``shrink``: the wall made thinner and the slot wider by this much on each side.
    """
    in_wall = (q[:, 0] > 0.45 + shrink) & (q[:, 0] < 0.55 - shrink)
    in_slot = (q[:, 1] > 0.45 - shrink) & (q[:, 1] < 0.5 + shrink)
    return np.asarray(~in_wall | in_slot)


def eroded(q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The wall shrunk by the check's resolution: an edge may clip a corner by less."""
    return wall_with_slot(q, RrtSettings().resolution_m)


def densely_valid(path: NDArray[np.float64], valid: object, spacing: float = 1e-3) -> bool:
    for a, b in itertools.pairwise(path):
        count = int(np.ceil(np.abs(b - a).sum() / spacing)) + 1
        points = a + np.linspace(0.0, 1.0, count)[:, None] * (b - a)
        if not valid(points).all():  # type: ignore[operator]
            return False
    return True


@pytest.mark.parametrize("seed", range(5))
def test_finds_the_slot_and_every_edge_is_valid(seed: int) -> None:
    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    found = rrt_connect(wall_with_slot, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(seed))
    assert found is not None
    path = found.path
    np.testing.assert_array_equal(path[0], start)
    np.testing.assert_array_equal(path[-1], goal)
    # edges are checked every 0.01: between two checks they clip a corner by less than that
    assert densely_valid(path, eroded)
    assert found.samples >= 1 and found.checks > 0
    # where it crosses x = 0.5 it is in the slot
    crossings = [
        a[1] + (0.5 - a[0]) / (b[0] - a[0]) * (b[1] - a[1])
        for a, b in itertools.pairwise(path)
        if (a[0] - 0.5) * (b[0] - 0.5) < 0
    ]
    assert crossings and all(0.44 < y < 0.51 for y in crossings)


def test_shortcuts_make_the_path_at_most_as_long() -> None:
    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    lengths = []
    for shortcuts in (0, 200):
        found = rrt_connect(
            wall_with_slot,
            start,
            goal,
            LOWER,
            UPPER,
            WEIGHTS,
            np.random.default_rng(3),
            RrtSettings(shortcuts=shortcuts),
        )
        assert found is not None
        lengths.append(float(np.abs(np.diff(found.path, axis=0)).sum()))
    assert lengths[1] <= lengths[0] + 1e-12
    # the shortest way through the slot, in the L1 metric, is at least |dx| + |dy| = 1.6
    assert lengths[1] >= 1.6 - 1e-9


def test_a_clear_line_is_the_path_with_no_sample() -> None:
    found = rrt_connect(
        lambda q: np.ones(len(q), dtype=bool),
        np.zeros(2),
        np.ones(2),
        LOWER,
        UPPER,
        WEIGHTS,
        np.random.default_rng(0),
    )
    assert found is not None and found.samples == 0
    np.testing.assert_array_equal(found.path, [[0.0, 0.0], [1.0, 1.0]])


def test_a_closed_wall_gives_none_after_the_budget() -> None:
    def closed(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        return np.asarray(~((q[:, 0] > 0.45) & (q[:, 0] < 0.55)))

    found = rrt_connect(
        closed,
        np.array([0.1, 0.5]),
        np.array([0.9, 0.5]),
        LOWER,
        UPPER,
        WEIGHTS,
        np.random.default_rng(0),
        RrtSettings(max_samples=300),
    )
    assert found is None


def test_same_generator_seed_same_path() -> None:
    def run() -> NDArray[np.float64]:
        found = rrt_connect(
            wall_with_slot,
            np.array([0.1, 0.9]),
            np.array([0.9, 0.1]),
            LOWER,
            UPPER,
            WEIGHTS,
            np.random.default_rng(11),
        )
        assert found is not None
        return found.path

    np.testing.assert_array_equal(run(), run())


@pytest.mark.parametrize("step_m", [None, 0.1])
def test_an_extension_is_at_most_one_step(step_m: float | None, monkeypatch: pytest.MonkeyPatch) -> None:
    """The default step is a fifth of the box's diagonal in the weighted motion bound."""
    import planning.search.edges

    monkeypatch.setattr(planning.search.edges, "WHOLE_BELOW", 10**9)  # one batch per call: all, in order
    weights = np.array([2.0, 0.5])
    batches: list[NDArray[np.float64]] = []

    def recorded(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        batches.append(q.copy())
        return wall_with_slot(q)

    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    settings = RrtSettings(step_m=step_m, resolution_m=0.01)
    rrt_connect(recorded, start, goal, LOWER, UPPER, weights, np.random.default_rng(0), settings)
    step = 0.2 * float(np.hypot(2.0, 0.5)) if step_m is None else step_m
    # batch 0 checks the ends, 1 is the straight line, 2 the first extension from the start (then a
    # connection)
    np.testing.assert_array_equal(batches[0], [start, goal])
    count = math.ceil(step / 0.01 - 1e-9)
    reach = np.abs(batches[2] - start) @ weights
    assert reach[:count].max() <= step * (1 + 1e-9)
    assert reach[:count].max() >= step - 0.01  # the first sample lies farther than one step


def test_an_invalid_end_is_no_path_at_once() -> None:
    """A goal inside the wall: one call of the validity check, no sample spent."""
    calls: list[int] = []

    def counted(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        calls.append(len(q))
        return wall_with_slot(q)

    start, goal = np.array([0.1, 0.9]), np.array([0.5, 0.1])
    assert not wall_with_slot(goal[None])[0]
    assert rrt_connect(counted, start, goal, LOWER, UPPER, np.ones(2), np.random.default_rng(0)) is None
    assert calls == [2]


def thin_wall(q: NDArray[np.float64], shrink: float = 0.0) -> NDArray[np.bool_]:
    """A wall 1 cm thick at ``x = 0.5`` with the slot ``0.45 < y < 0.5``: a 5 cm check steps over it."""
    in_wall = (q[:, 0] > 0.495 + shrink) & (q[:, 0] < 0.505 - shrink)
    in_slot = (q[:, 1] > 0.45 - shrink) & (q[:, 1] < 0.5 + shrink)
    return np.asarray(~in_wall | in_slot)


def test_trees_grown_on_coarse_checks_return_a_path_that_holds_at_the_fine_spacing() -> None:
    """Edges checked every 5 cm jump the 1 cm wall anywhere; the path returned is checked every
    2 mm, its blocked edges planned again: it crosses in the slot, with fewer checks in all
    than growing the trees on the fine spacing."""
    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    fine = RrtSettings(resolution_m=0.002)
    lazy = RrtSettings(resolution_m=0.002, explore_resolution_m=0.05)
    checks = {"fine": 0, "lazy": 0}
    for seed in range(5):
        for name, settings in (("fine", fine), ("lazy", lazy)):
            found = rrt_connect(
                thin_wall, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(seed), settings
            )
            assert found is not None
            np.testing.assert_array_equal(found.path[[0, -1]], [start, goal])
            assert densely_valid(found.path, lambda q: thin_wall(q, 0.002))
            checks[name] += found.checks
    assert checks["lazy"] < checks["fine"]
    with pytest.raises(PlanningError, match="explore_resolution_m"):
        RrtSettings(resolution_m=0.01, explore_resolution_m=0.005)


def test_settings_and_weights_are_validated() -> None:
    with pytest.raises(PlanningError, match="step_m"):
        RrtSettings(step_m=0.0)
    with pytest.raises(PlanningError, match="resolution_m"):
        RrtSettings(step_m=0.1, resolution_m=0.2)
    with pytest.raises(PlanningError, match="local_share"):
        RrtSettings(local_share=1.5)
    with pytest.raises(PlanningError, match="local_spread"):
        RrtSettings(local_spread=0.0)
    with pytest.raises(PlanningError, match="weights"):
        rrt_connect(wall_with_slot, LOWER, UPPER, LOWER, UPPER, -WEIGHTS, np.random.default_rng(0))
    with pytest.raises(PlanningError, match="joint_shortcuts"):
        RrtSettings(joint_shortcuts=-1)
    for speeds in (np.array([1.0, 0.0]), np.array([1.0, np.inf]), np.ones(3)):
        with pytest.raises(PlanningError, match=r"speeds \[.*\] must be positive and finite, one per joint"):
            rrt_connect(
                wall_with_slot, LOWER, UPPER, LOWER, UPPER, WEIGHTS, np.random.default_rng(0), speeds=speeds
            )


def test_given_the_speeds_the_path_is_as_fast_or_faster_and_as_valid() -> None:
    """The maze with a third, slow joint that no wall constrains: the trees move it at random, the
    same draws' paths straightened in it are never slower, and every edge stays valid."""

    def slotted(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        return wall_with_slot(q[:, :2])

    start, goal = np.array([0.1, 0.9, 0.5]), np.array([0.9, 0.1, 0.5])
    lower, upper, weights = np.zeros(3), np.ones(3), np.ones(3)
    speeds = np.array([1.0, 1.0, 0.05])
    straightening = RrtSettings(joint_shortcuts=20)
    faster = 0
    for seed in range(5):
        paths = [
            rrt_connect(
                slotted,
                start,
                goal,
                lower,
                upper,
                weights,
                np.random.default_rng(seed),
                straightening,
                speeds=given,
            )
            for given in (None, speeds)
        ]
        assert paths[0] is not None and paths[1] is not None
        assert path_time(paths[1].path, speeds) <= path_time(paths[0].path, speeds)
        faster += path_time(paths[1].path, speeds) < path_time(paths[0].path, speeds)
        assert densely_valid(paths[1].path, lambda q: eroded(q[:, :2]))
        np.testing.assert_array_equal(paths[1].path[[0, -1]], [start, goal])
    assert faster > 0  # some draw's path was straightened


@pytest.mark.parametrize("seed", range(3))
def test_local_samples_are_drawn_about_the_trees_nodes(seed: int, monkeypatch: pytest.MonkeyPatch) -> None:
    """Every sample local, of a small spread: the first extension ends a few spreads from the start.

    Uniform samples put it a whole step away (a fifth of the box's diagonal, 0.28 here).
    """
    import planning.search.edges

    monkeypatch.setattr(planning.search.edges, "WHOLE_BELOW", 10**9)  # one batch per call: all, in order
    batches: list[NDArray[np.float64]] = []

    def recorded(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        batches.append(q.copy())
        return wall_with_slot(q)

    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    settings = RrtSettings(resolution_m=0.01, local_share=1.0, local_spread=0.01)
    rrt_connect(recorded, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(seed), settings)
    # batch 0 checks the ends, 1 the straight line, 2 the first extension from the start
    assert np.abs(batches[2][-1] - start).max() < 5 * 0.01
    uniform = dataclasses.replace(settings, local_share=0.0)
    batches.clear()
    rrt_connect(recorded, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(seed), uniform)
    assert np.abs(batches[2][-1] - start).max() > 5 * 0.01


def test_waypoints_keep_the_corners_and_split_the_longest_pieces() -> None:
    path = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 3.0]])
    points = waypoints_along(path, 3, WEIGHTS)
    # the corner kept, the 3-long piece split in three
    np.testing.assert_allclose(points, [[1.0, 0.0], [1.0, 1.0], [1.0, 2.0]])
    # fewer waypoints than corners: evenly spaced in arc length (total 4: at 1, 2, 3)
    zigzag = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [2.0, 1.0], [2.0, 2.0]])
    np.testing.assert_allclose(waypoints_along(zigzag, 1, WEIGHTS), [[1.0, 1.0]])
    assert waypoints_along(path, 1, WEIGHTS).shape == (1, 2)


def closed_wall(q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The wall with its slot closed: no way across (a clearance larger than the slot)."""
    return np.asarray((q[:, 0] <= 0.45) | (q[:, 0] >= 0.55))


def test_a_relaxation_lets_the_trees_through_after_its_samples() -> None:
    """Under the strict validity there is no way; after ``after_samples`` the trees go on under
    the looser one (the slot open), keep what they grew, and the path holds only under it."""
    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    settings = RrtSettings(max_samples=2000)
    assert (
        rrt_connect(closed_wall, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(0), settings)
        is None
    )
    relaxation = Relaxation(wall_with_slot, after_samples=100)
    found = rrt_connect(
        closed_wall,
        start,
        goal,
        LOWER,
        UPPER,
        WEIGHTS,
        np.random.default_rng(0),
        settings,
        relaxation=relaxation,
    )
    assert found is not None and found.relaxed and 100 < found.samples <= 2000
    assert densely_valid(found.path, eroded) and not densely_valid(found.path, closed_wall)


def test_a_relaxation_changes_nothing_before_its_samples_and_holds_at_once_for_ends_that_need_it() -> None:
    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    plain = rrt_connect(wall_with_slot, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(3))
    late = Relaxation(lambda q: np.ones(len(q), dtype=bool), after_samples=10_000)
    relaxable = rrt_connect(
        wall_with_slot, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(3), relaxation=late
    )
    assert plain is not None and relaxable is not None and not relaxable.relaxed
    np.testing.assert_array_equal(plain.path, relaxable.path)
    in_the_wall = np.array([0.46, 0.9])  # an end only the looser validity accepts
    assert (
        rrt_connect(wall_with_slot, in_the_wall, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(0))
        is None
    )
    thin = Relaxation(lambda q: wall_with_slot(q, shrink=0.02), after_samples=10_000)
    found = rrt_connect(
        wall_with_slot, in_the_wall, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(0), relaxation=thin
    )
    assert found is not None and found.relaxed
    # held at the check's resolution: the looser wall eroded by it, as `eroded` for the strict one
    assert densely_valid(found.path, lambda q: wall_with_slot(q, 0.02 + RrtSettings().resolution_m))


def test_the_samplers_uniform_draws_are_numpys_uniform_to_the_bit() -> None:
    # the identity the sampler's shortcut rests on: low + (high - low) * u from the same u
    lower, upper = np.array([-2.9, 0.0, 0.05, -3.1, -1e-3]), np.array([2.9, 0.6, 0.5, 3.1, 2.5])
    sampler = Sampler(lower, upper, dataclasses.replace(RrtSettings(), local_share=0.0))
    ours, numpys = np.random.default_rng(12), np.random.default_rng(12)
    root = Tree(np.zeros(5))
    for _ in range(500):
        np.testing.assert_array_equal(sampler(root, ours), numpys.uniform(lower, upper))
    local = Sampler(lower, upper, dataclasses.replace(RrtSettings(), local_share=0.5))
    ours, numpys = np.random.default_rng(13), np.random.default_rng(13)
    for _ in range(500):  # the share's coin is rng.uniform()'s number too
        drawn = local(root, ours)
        if numpys.uniform() < 0.5:
            numpys.integers(root.size)
            expected = np.clip(numpys.standard_normal(5) * local.spread, lower, upper)
        else:
            expected = numpys.uniform(lower, upper)
        np.testing.assert_array_equal(drawn, expected)


class Counted:
    """A validity that counts the configurations it checks (the expensive check of a screened one)."""

    def __init__(self, valid: object) -> None:
        self.valid, self.checked = valid, 0

    def __call__(self, q: NDArray[np.float64]) -> NDArray[np.bool_]:
        self.checked += len(q)
        return self.valid(q)  # type: ignore[operator, no-any-return]


def beside_the_wall(q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The wall with its slot, and a post off the way the screen leaves out (an arm's own pairs)."""
    post = np.hypot(q[:, 0] - 0.8, q[:, 1] - 0.8) < 0.1
    return np.asarray(wall_with_slot(q) & ~post)


LAZY = RrtSettings(resolution_m=0.002, explore_resolution_m=0.05)


@pytest.mark.parametrize("seed", range(6))
def test_trees_grown_on_a_screen_give_a_path_that_holds_under_the_validity(seed: int) -> None:
    """The trees grow on the wall alone; the path returned also keeps off the post the screen
    left out, held at the fine spacing, with fewer configurations checked by the validity (only
    the path's, not every edge the trees tried)."""
    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    counts = []
    for screened in (False, True):
        full = Counted(beside_the_wall)
        valid = ScreenedValidity(full, wall_with_slot) if screened else full
        found = rrt_connect(valid, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(seed), LAZY)
        assert found is not None
        np.testing.assert_array_equal(found.path[[0, -1]], [start, goal])
        assert densely_valid(found.path, eroded_beside_the_wall)
        counts.append(full.checked)
    assert counts[1] < counts[0]


def eroded_beside_the_wall(q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The wall and the post shrunk by the fine check's spacing: an edge may clip them by less."""
    post = np.hypot(q[:, 0] - 0.8, q[:, 1] - 0.8) < 0.1 - 0.002
    return np.asarray(wall_with_slot(q, 0.002) & ~post)


@pytest.mark.parametrize("seed", range(4))
def test_a_screened_path_through_a_way_only_the_screen_opens_is_held_under_the_validity(seed: int) -> None:
    """The screen opens the wall's top, where the straight line runs; the validity closes it:
    the path returned crosses in the slot."""
    start, goal = np.array([0.1, 0.95]), np.array([0.9, 0.95])

    def open_at_the_top(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        return np.asarray(wall_with_slot(q) | (q[:, 1] > 0.9))

    valid = ScreenedValidity(wall_with_slot, open_at_the_top)
    found = rrt_connect(valid, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(seed), LAZY)
    assert found is not None and not found.relaxed
    np.testing.assert_array_equal(found.path[[0, -1]], [start, goal])
    assert densely_valid(found.path, lambda q: wall_with_slot(q, 0.002))


def test_a_screened_relaxation_holds_its_path_under_its_validity() -> None:
    """An end only the looser validity accepts: the trees grow on the looser one's screen, and the
    path holds under the looser validity, not under its screen alone."""
    in_the_wall, goal = np.array([0.46, 0.9]), np.array([0.9, 0.1])

    def thinner(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        return wall_with_slot(q, shrink=0.02)

    def thinner_beside_the_post(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        return np.asarray(thinner(q) & ~(np.hypot(q[:, 0] - 0.7, q[:, 1] - 0.35) < 0.1))

    strict = ScreenedValidity(beside_the_wall, wall_with_slot)
    relaxation = Relaxation(ScreenedValidity(thinner_beside_the_post, thinner), after_samples=10_000)
    found = rrt_connect(
        strict,
        in_the_wall,
        goal,
        LOWER,
        UPPER,
        WEIGHTS,
        np.random.default_rng(0),
        LAZY,
        relaxation=relaxation,
    )
    assert found is not None and found.relaxed

    def eroded(q: NDArray[np.float64]) -> NDArray[np.bool_]:  # by the fine check's spacing
        post = np.hypot(q[:, 0] - 0.7, q[:, 1] - 0.35) < 0.1 - 0.002
        return np.asarray(wall_with_slot(q, 0.022) & ~post)

    assert densely_valid(found.path, eroded)


def test_a_validity_s_screen() -> None:
    screened = ScreenedValidity(beside_the_wall, wall_with_slot)
    assert screen_of(screened) is wall_with_slot and screen_of(wall_with_slot) is None
    q = np.array([[0.8, 0.8], [0.5, 0.9]])  # on the post; in the wall
    np.testing.assert_array_equal(screened(q), [False, False])
    np.testing.assert_array_equal(screen_of(screened)(q), [True, False])  # type: ignore[misc]


def test_where_a_screened_path_does_not_hold_the_coarse_draw_is_made_again_on_the_validity(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A band the screen leaves out crosses every way to the slot but at its far left: the trees
    grown on the screen cross it anywhere; where their path's vertex lies in it, or an edge
    through it finds no detour, the trees grow again on the validity. Every path holds."""
    import planning.search.rrt_connect as module

    def banded(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        band = (q[:, 1] > 0.5) & (q[:, 1] < 0.85) & (q[:, 0] > 0.08) & (q[:, 0] < 0.45)
        return np.asarray(wall_with_slot(q) & ~band)

    def eroded_banded(q: NDArray[np.float64]) -> NDArray[np.bool_]:
        band = (q[:, 1] > 0.502) & (q[:, 1] < 0.848) & (q[:, 0] > 0.082) & (q[:, 0] < 0.448)
        return np.asarray(wall_with_slot(q, 0.002) & ~band)

    valid = ScreenedValidity(banded, wall_with_slot)
    draws = []
    original = module.rrt_connect

    def counted(check: object, *args: object, **kwargs: object) -> object:
        settings = args[6] if len(args) > 6 else None
        if check is valid and isinstance(settings, RrtSettings) and settings.resolution_m == 0.05:
            draws.append(check)  # a coarse draw on the validity itself
        return original(check, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(module, "rrt_connect", counted)
    start, goal = np.array([0.1, 0.9]), np.array([0.9, 0.1])
    for seed in range(8):
        found = counted(valid, start, goal, LOWER, UPPER, WEIGHTS, np.random.default_rng(seed), LAZY)
        assert isinstance(found, RrtPath)
        np.testing.assert_array_equal(found.path[[0, -1]], [start, goal])
        assert densely_valid(found.path, eroded_banded)
    assert draws  # some screened path did not hold
