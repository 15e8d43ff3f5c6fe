from __future__ import annotations

import argparse

import pytest

from planning.bench.mbm import CLASSES
from planning.bench.problem_selection import PER_CLASS, add_selection, check_selection, selected_problems


def parsed(arguments: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser()
    add_selection(parser)
    args = parser.parse_args(arguments)
    check_selection(parser, args)
    return args


def test_the_defaults_are_every_class_of_both_arms_and_every_problem() -> None:
    args = parsed([])
    assert args.robots == ["panda", "ur5"] and args.classes == list(CLASSES)
    assert args.limit is None and args.sample_seed is None


def test_a_sample_is_a_limit_and_a_seed() -> None:
    args = parsed(["--robots", "fetch", "--classes", "cage", "box", "--limit", "3", "--sample-seed", "7"])
    assert (args.robots, args.classes, args.limit, args.sample_seed) == (["fetch"], ["cage", "box"], 3, 7)
    assert parsed(["--limit", str(PER_CLASS)]).limit == PER_CLASS


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (
            ["--limit", str(PER_CLASS + 1)],
            f"--limit {PER_CLASS + 1} must be in [1, {PER_CLASS}] problems per class",
        ),
        (["--sample-seed", "3"], "--sample-seed 3 goes with --limit (the sample's size per class)"),
        (["--limit", "0"], "argument --limit: 0 must be an integer >= 1"),
        (["--robots", "kuka"], "argument --robots: invalid choice: 'kuka'"),
        (["--classes", "shelf"], "argument --classes: invalid choice: 'shelf'"),
        (["--names", "box_0020", "shelf_0001"], "--names shelf_0001: a problem is <class>_<number 1-100>"),
        (["--names", "box_0101"], "--names box_0101: a problem is <class>_<number 1-100>"),
    ],
)
def test_a_bad_selection_is_one_line_and_exit_2(
    arguments: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as info:
        parsed(arguments)
    assert info.value.code == 2
    assert message in capsys.readouterr().err


def test_names_keep_only_the_problems_named() -> None:
    args = parsed(["--robots", "ur5", "--names", "box_0020", "cage_0003", "--classes", "box"])
    chosen = [p.name for p in selected_problems(args, "ur5")]
    assert chosen == ["box_0020"]  # the classes still select: cage is not among them
