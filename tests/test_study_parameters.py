"""``scripts/study_parameters.py``: variants interleaved problem by problem, constants set for their own."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

import planning.curves.velocity_caps as velocity_caps

from .conftest import load_script

EXAMPLES = Path(__file__).resolve().parents[1] / "examples" / "scenes"


def rows(printed: str) -> dict[str, list[str]]:
    """The study's table: each variant's cells by its name (the name is left of the first count)."""
    table = {}
    for line in printed.splitlines():
        found = re.match(r"(.+?)\s+(\d+)/(\d+)\s+(.*)", line)
        if found:
            table[found[1]] = [found[2], found[3], *found[4].split()]
    return table


def test_a_constant_variant_times_its_own_plans_only_and_the_defaults_come_first(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    study = load_script("study_parameters")
    grid = "timing grid 50 steps a ramp"
    argv = ["study_parameters.py", "--scenes", "3", "--narrow", "0", "--variants", grid, "--per-class"]
    monkeypatch.setattr("sys.argv", argv)
    assert study.main() == 0
    table = rows(capsys.readouterr().out)
    assert list(table) == ["defaults", grid]
    defaults, coarser = table["defaults"], table[grid]
    assert defaults[:2] == coarser[:2] == ["3", "3"]  # every scene planned by both
    assert defaults[7] == "1.0000"  # the reference against itself
    assert coarser[7] != "1.0000"  # the coarser grid timed its plans: other durations
    assert velocity_caps.STEPS_PER_RAMP == 100  # and was put back


def test_a_variants_constants_are_restored_when_its_plan_fails() -> None:
    study = load_script("study_parameters")
    variant = study.timing_grid(7)
    with pytest.raises(RuntimeError), variant.applied():
        assert velocity_caps.STEPS_PER_RAMP == 7
        raise RuntimeError("a plan that fails")
    assert velocity_caps.STEPS_PER_RAMP == 100


def test_scene_files_of_any_robot_are_studied_with_a_time_limit(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    study = load_script("study_parameters")
    files = [str(EXAMPLES / "shelf.yaml"), str(EXAMPLES / "panda_post.yaml")]
    argv = ["study_parameters.py", "--files", *files, "--variants", "refinement stall 3"]
    monkeypatch.setattr("sys.argv", argv)
    assert study.main() == 0
    printed = capsys.readouterr().out
    assert printed.startswith("2 problems")
    table = rows(printed)
    assert table["defaults"][:2] == table["refinement stall 3"][:2] == ["2", "2"]
    assert float(table["defaults"][6]) >= 1.0  # no trajectory is shorter than Ruckig's bound


def test_a_task_file_is_refused_in_one_line(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    study = load_script("study_parameters")
    monkeypatch.setattr("sys.argv", ["study_parameters.py", "--files", str(EXAMPLES / "pick_and_place.yaml")])
    with pytest.raises(SystemExit) as info:
        study.main()
    assert info.value.code == 2
    last = capsys.readouterr().err.strip().splitlines()[-1]  # argparse's usage, then the fault
    assert (
        last.startswith("study_parameters.py: error: ") and "pick_and_place.yaml" in last and "task" in last
    )
