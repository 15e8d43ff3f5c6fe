"""The scripts' argument types (planning.cli.arguments): bounds kept, bad values one line, exit 2."""

from __future__ import annotations

import argparse
import math

import pytest

from planning.cli.arguments import COUNT, SECONDS, SEED, integer_at_least, number_above, number_at_least
from tests.conftest import load_script


@pytest.mark.parametrize("low", [-3, 0, 1, 7])
def test_an_integer_is_taken_from_its_bound_up_and_refused_below(low: int) -> None:
    parse = integer_at_least(low)
    assert [parse(str(value)) for value in (low, low + 1, low + 1000)] == [low, low + 1, low + 1000]
    for text in (str(low - 1), "1.5", "ten", ""):
        with pytest.raises(argparse.ArgumentTypeError, match=f"must be an integer >= {low}"):
            parse(text)


def test_a_number_must_be_finite_and_above_its_bound() -> None:
    parse = number_above(0.5, "m")
    assert parse("0.5000001") == pytest.approx(0.5000001) and parse("2") == 2.0
    for text in ("0.5", "-1", "nan", "inf", "x"):
        with pytest.raises(argparse.ArgumentTypeError, match=r"must be a number > 0.5 m"):
            parse(text)
    assert SEED("0") == 0 and COUNT("1") == 1 and math.isclose(SECONDS("0.01"), 0.01)


def test_a_number_at_least_its_bound_takes_the_bound_itself() -> None:
    parse = number_at_least(0.0, "m")
    assert parse("0") == 0.0 and parse("0.02") == 0.02
    for text in ("-0.001", "nan", "-inf", "x"):
        with pytest.raises(argparse.ArgumentTypeError, match=r"must be a number >= 0 m"):
            parse(text)


@pytest.mark.parametrize(
    ("script", "arguments", "message"),
    [
        ("bench_batch", ["--runs", "0"], "argument --runs: 0 must be an integer >= 1"),
        ("bench_hostile", ["--timeout", "-1"], "argument --timeout: -1 must be a number > 0 s"),
        ("bench_ik", ["--seed", "-1"], "argument --seed: -1 must be an integer >= 0"),
        ("bench_peers", ["--scenes", "-1"], "argument --scenes: -1 must be an integer >= 0"),
        ("bench_planner", ["--runs", "0"], "argument --runs: 0 must be an integer >= 1"),
        ("bench_library_loop", ["--rounds", "0"], "argument --rounds: 0 must be an integer >= 1"),
        ("bench_startup", ["--runs", "0"], "argument --runs: 0 must be an integer >= 1"),
        (
            "bench_startup",
            ["--compare", "/"],
            "argument --compare: / is not a checkout of this project (no planning/ package)",
        ),
        (
            "bench_batch",
            ["--compare", "/"],
            "argument --compare: / is not a checkout of this project (no planning/ package)",
        ),
        ("bench_timing", ["--rrt-time", "0"], "argument --rrt-time: 0 must be a number > 0 s"),
        ("bench_torque", ["--limit", "-1"], "argument --limit: -1 must be an integer >= 1"),
        ("bench_torque", ["--limit", "101"], "--limit 101 must be in [1, 100] problems per class"),
        ("generate_scenes", ["--seed", "-1", "--out", "x"], "argument --seed: -1 must be an integer >= 0"),
        ("study_parameters", ["--narrow", "-1"], "argument --narrow: -1 must be an integer >= 0"),
        (
            "study_parameters",
            ["--variants", "stall 9"],
            "--variants ['stall 9']: not variants of this study; its variants: ['1 path attempt'",
        ),
        ("study_parameters", ["--files", "x.yaml", "--mbm"], "give --files or --mbm, not both"),
        ("paper_case", ["--seeds", "0"], "argument --seeds: 0 must be an integer >= 1"),
        (
            "generate_arm_scenes",
            ["--robot", "ur5", "--margin", "-0.01", "--out", "x"],
            "argument --margin: -0.01 must be a number >= 0 m",
        ),
        (
            "generate_arm_scenes",
            ["--robot", "ur5", "--self-clearance", "0", "--out", "x"],
            "argument --self-clearance: 0 must be a number > 0 m",
        ),
    ],
)
def test_a_script_names_a_bad_value_before_it_runs(
    script: str,
    arguments: list[str],
    message: str,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    module = load_script(script)
    monkeypatch.setattr("sys.argv", [f"{script}.py", *arguments])
    with pytest.raises(SystemExit) as info:
        module.main()
    assert info.value.code == 2
    assert message in capsys.readouterr().err
