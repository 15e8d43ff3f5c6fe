"""The trees a draw that found no path leaves, gone on with by the next draw between the same ends."""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
import pytest
from numpy.typing import NDArray

from planning.search.rrt_connect import Relaxation, RrtPath, rrt_connect
from planning.search.rrt_settings import RrtSettings
from planning.search.rrt_trees import GrownTrees, Tree

from .test_rrt_connect import LOWER, UPPER, WEIGHTS, densely_valid, wall_with_slot

START, GOAL = np.array([0.1, 0.9]), np.array([0.9, 0.1])


def narrow(q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """A thicker wall with a slot a centimetre wide: tens to hundreds of samples to pass."""
    return wall_with_slot(q, -0.015)


def wide(q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The wall and slot of :func:`wall_with_slot`: accepts everything :func:`narrow` accepts."""
    return wall_with_slot(q)


def stopped_after(samples: int) -> Callable[[], bool]:
    calls: list[int] = []

    def stop() -> bool:
        calls.append(1)
        return len(calls) > samples

    return stop


@pytest.mark.parametrize(("seed", "first"), [(1, 100), (2, 400), (3, 30)])
def test_a_draw_gone_on_with_is_the_draw_uninterrupted(seed: int, first: int) -> None:
    """Stopped after ``first`` samples, continued from the same stream: the same path and samples."""
    whole = rrt_connect(narrow, START, GOAL, LOWER, UPPER, WEIGHTS, np.random.default_rng(seed))
    assert whole is not None and whole.samples > first
    grown, rng = GrownTrees(), np.random.default_rng(seed)
    cut = rrt_connect(narrow, START, GOAL, LOWER, UPPER, WEIGHTS, rng, stop=stopped_after(first), grown=grown)
    assert cut is None and grown.nodes > 2  # the roots and what grew from them
    again = rrt_connect(narrow, START, GOAL, LOWER, UPPER, WEIGHTS, rng, grown=grown)
    assert again is not None and again.samples == whole.samples - first
    np.testing.assert_array_equal(again.path, whole.path)
    assert grown.nodes == 0  # taken: a draw that finds a path leaves none


def test_a_looser_validity_goes_on_with_the_stricter_ones_trees() -> None:
    grown = GrownTrees()
    strict = rrt_connect(
        narrow,
        START,
        GOAL,
        LOWER,
        UPPER,
        WEIGHTS,
        np.random.default_rng(2),
        stop=stopped_after(50),
        grown=grown,
    )
    kept = grown.nodes
    assert strict is None and kept > 2
    looser = rrt_connect(wide, START, GOAL, LOWER, UPPER, WEIGHTS, np.random.default_rng(9), grown=grown)
    assert looser is not None and densely_valid(looser.path, lambda q: wall_with_slot(q, 0.01))
    assert grown.nodes == 0


def test_trees_are_taken_only_between_the_same_ends_at_the_same_spacing() -> None:
    grown = GrownTrees()
    tree = Tree(START)
    grown.keep((tree, Tree(GOAL)), START, GOAL, 0.01, relaxed=False)
    assert grown.take(START, GOAL, 0.02, relaxable=False) is None and grown.nodes == 0  # another spacing
    grown.keep((tree, Tree(GOAL)), START, GOAL, 0.01, relaxed=False)
    assert grown.take(GOAL, START, 0.01, relaxable=False) is None  # the ends swapped
    grown.keep((tree, Tree(GOAL)), START, GOAL, 0.01, relaxed=True)
    assert grown.take(START, GOAL, 0.01, relaxable=False) is None  # they need a relaxation
    grown.keep((tree, Tree(GOAL)), START, GOAL, 0.01, relaxed=True)
    taken = grown.take(START.copy(), GOAL.copy(), 0.01, relaxable=True)
    assert taken is not None and taken[0] is tree and grown.relaxed


def closed(q: NDArray[np.float64]) -> NDArray[np.bool_]:
    """The slot closed: no path."""
    return wall_with_slot(q, -0.06)


def draw(
    valid: Callable[[NDArray[np.float64]], NDArray[np.bool_]],
    grown: GrownTrees,
    settings: RrtSettings | None = None,
    stop: Callable[[], bool] | None = None,
    relaxation: Relaxation | None = None,
) -> RrtPath | None:
    rng = np.random.default_rng(0)
    return rrt_connect(valid, START, GOAL, LOWER, UPPER, WEIGHTS, rng, settings, stop, relaxation, grown)


def test_trees_grown_under_a_relaxation_go_on_only_under_one() -> None:
    """Kept as relaxed: a draw without a relaxation grows its own, one with goes on under it at once."""
    grown = GrownTrees()
    assert draw(closed, grown, stop=stopped_after(8), relaxation=Relaxation(narrow, 5)) is None
    assert grown.relaxed and grown.nodes > 2
    assert draw(closed, grown, stop=stopped_after(0)) is None  # not taken: its own roots kept
    assert grown.nodes == 2 and not grown.relaxed
    draw(closed, grown, stop=stopped_after(8), relaxation=Relaxation(narrow, 5))
    found = draw(closed, grown, relaxation=Relaxation(narrow, 10**6))  # under it at once, though later
    assert found is not None and found.relaxed and grown.nodes == 0
    assert densely_valid(found.path, lambda q: wall_with_slot(q, -0.005))


def test_the_trees_of_ends_that_need_the_relaxation_are_kept_as_relaxed() -> None:
    """The ends fail the strict validity: the trees grow under the looser one; a coarse draw keeps none."""
    strict = lambda q: narrow(q) & (np.abs(q - START).sum(axis=1) > 0.05)  # noqa: E731 - the start refused
    relaxation = Relaxation(closed, after_samples=1000)
    grown = GrownTrees()
    assert draw(strict, grown, settings=RrtSettings(), stop=stopped_after(20), relaxation=relaxation) is None
    assert grown.relaxed and grown.nodes > 2
    coarse, grown = dataclasses.replace(RrtSettings(), explore_resolution_m=0.04), GrownTrees()
    assert draw(strict, grown, settings=coarse, stop=stopped_after(20), relaxation=relaxation) is None
    assert grown.nodes == 0


def test_agreement_is_asked_only_when_there_are_trees_to_take() -> None:
    asked: list[bool] = []

    def agree(answer: bool) -> Callable[[], bool]:
        def said() -> bool:
            asked.append(answer)
            return answer

        return said

    grown = GrownTrees(agree(False))
    assert grown.take(START, GOAL, 0.01, relaxable=True) is None and asked == []  # nothing kept: not asked
    grown.keep((Tree(START), Tree(GOAL)), START, GOAL, 0.01, relaxed=False)
    assert grown.take(START, GOAL, 0.01, relaxable=True) is None and asked == [False]
    grown = GrownTrees(agree(True))
    grown.keep((Tree(START), Tree(GOAL)), START, GOAL, 0.01, relaxed=False)
    assert grown.take(START, GOAL, 0.01, relaxable=True) is not None and asked == [False, True]
