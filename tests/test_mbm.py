"""MotionBenchMaker's problems: which ones ``problems`` gives, first or drawn (planning.bench.mbm)."""

from __future__ import annotations

import pytest

from planning.bench.mbm import CLASSES, problems
from planning.errors import PlanningError


def indices(
    classes: tuple[str, ...], limit: int | None, sample_seed: int | None = None
) -> dict[str, list[int]]:
    """Each class's problem numbers, as ``problems`` gives them for the Panda."""
    found: dict[str, list[int]] = {}
    for problem in problems("panda", classes, limit, sample_seed):
        assert problem.scene.is_file() and problem.request.is_file()
        found.setdefault(problem.problem_class, []).append(problem.index)
    return found


def test_every_class_holds_a_hundred_problems_and_a_limit_takes_the_first() -> None:
    every = indices(CLASSES, None)
    assert list(every) == list(CLASSES)
    assert all(numbers == list(range(1, 101)) for numbers in every.values())
    assert indices(("cage", "box"), 3) == {"cage": [1, 2, 3], "box": [1, 2, 3]}


def test_a_sample_is_its_seed_s_whatever_the_other_classes() -> None:
    drawn = indices(("box", "cage"), 8, sample_seed=5)
    assert drawn == indices(("box", "cage"), 8, sample_seed=5)  # the same seed, the same problems
    assert drawn["cage"] == indices(("cage",), 8, sample_seed=5)["cage"]  # one generator a class
    for numbers in drawn.values():
        assert len(numbers) == len(set(numbers)) == 8 and numbers == sorted(numbers)
        assert set(numbers) <= set(range(1, 101))
    assert drawn != indices(("box", "cage"), 8, sample_seed=6)
    assert drawn["box"] != list(range(1, 9))  # not the first eight
    assert indices(("box",), None, sample_seed=5)["box"] == list(range(1, 101))  # no limit: all


@pytest.mark.parametrize(
    ("limit", "seed", "message"),
    [(0, None, "limit = 0 problems per class must be at least 1"), (3, -1, "sample_seed = -1 must be")],
)
def test_a_bad_limit_or_seed_is_named(limit: int, seed: int | None, message: str) -> None:
    with pytest.raises(PlanningError, match=message):
        next(problems("panda", ("box",), limit, seed))
