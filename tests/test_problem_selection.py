from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from planning.bench.mbm import CLASSES
from planning.bench.problem_selection import (
    PER_CLASS,
    Case,
    add_selection,
    check_selection,
    selected_cases,
    selected_problems,
)


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


def test_scene_folders_expand_to_their_scene_files_by_name(tmp_path: Path) -> None:
    folder = tmp_path / "arm"
    folder.mkdir()
    for name in ("b_2.yaml", "a_1.yaml", "notes.txt"):
        (folder / name).write_text("name: x\n")
    single = tmp_path / "c_3.yaml"
    single.write_text("name: y\n")
    plain = tmp_path / "shelf.yaml"
    plain.write_text("name: z\n")
    args = argparse.Namespace(scenes=[folder, single, plain])
    assert list(selected_cases(args, tmp_path / "out")) == [
        Case("arm", "a", 1, folder / "a_1.yaml"),
        Case("arm", "b", 2, folder / "b_2.yaml"),
        Case(tmp_path.name, "c", 3, single),
        Case(tmp_path.name, "shelf", 0, plain),  # no number: the whole name is its class
    ]
