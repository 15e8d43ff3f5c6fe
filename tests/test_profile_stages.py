"""``scripts/profile_stages.py``: exclusive stage times that add up to the plan's."""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
from pathlib import Path
from types import ModuleType

import pytest

from tests.conftest import load_script

SCRIPT = Path(__file__).resolve().parents[1] / "scripts" / "profile_stages.py"
SHELF = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "shelf.yaml"
TASK = SHELF.with_name("pick_and_place.yaml")


@pytest.fixture(scope="module")
def script() -> ModuleType:
    return load_script("profile_stages")


def test_a_stage_is_charged_its_own_time_not_that_of_the_stages_it_calls(script: ModuleType) -> None:
    now = [0.0]

    def tick(seconds: float) -> None:
        now[0] += seconds

    clock = script.StageClock(clock=lambda: now[0])

    def inner() -> None:
        tick(2.0)

    timed_inner = clock.wrapped("inner", inner)

    def outer() -> str:
        tick(1.0)
        timed_inner()
        tick(0.5)
        timed_inner()
        return "done"

    timed_outer = clock.wrapped("outer", outer)
    assert timed_outer() == "done" and timed_outer.__name__ == "outer"
    timed_inner()  # called alone: all its own
    assert clock.spent_s == {"outer": 1.5, "inner": 6.0}
    assert sum(clock.spent_s.values()) == now[0]  # the stages add up to the wall time


def test_the_table_gives_each_stage_s_median_and_share(script: ModuleType) -> None:
    stages = dict.fromkeys(script.STAGES, 0.0)
    rows = [
        script.Profiled("arm", "box", 1.0, {**stages, "refine": 0.5, "verify": 0.25}, 1.1, 2.0),
        script.Profiled("arm", "box", 3.0, {**stages, "refine": 1.5, "verify": 0.75}, 1.3, 3.0),
    ]
    lines = script.table(rows)
    box = next(line for line in lines if line.startswith("| arm | box |"))
    cells = [cell.strip() for cell in box.strip("|").split("|")]
    columns = [*script.STAGES, "other"]
    assert cells[2:6] == [
        "2",
        "2000.0",
        "1.200",
        "2.500",
    ]  # planned, plan [ms], duration / bound, duration [s]
    by_stage = dict(zip(columns, cells[6:], strict=True))
    assert by_stage["refine"] == "1000.0 (50%)" and by_stage["verify"] == "500.0 (25%)"
    assert by_stage["other"] == "500.0 (25%)"  # what no stage took
    assert any(line.startswith("| arm | all | 2 |") for line in lines)


def test_the_tail_holds_each_robot_s_plans_at_or_above_its_95th_percentile(script: ModuleType) -> None:
    stages = dict.fromkeys(script.STAGES, 0.0)
    # 40 plans of 1..40 s over two classes: the linear 95th percentile is 1 + 0.95 * 39 = 38.05 s
    rows = [script.Profiled("arm", ("box", "cage")[k % 2], float(k), stages, 1.0, 1.0) for k in range(1, 41)]
    rows.append(script.Profiled("other", "box", 5.0, stages, 1.0, 1.0))  # one plan: its own tail
    groups = script.by_class(rows)
    assert [key for key, _ in groups] == [
        ("arm", "cage"),  # the classes as first met (plan 1 is a cage's), then all, then the tail
        ("arm", "box"),
        ("arm", "all"),
        ("arm", script.TAIL),
        ("other", "box"),
        ("other", "all"),
        ("other", script.TAIL),
    ]
    tails = {key[0]: planned for key, planned in groups if key[1] == script.TAIL}
    assert [row.total_s for row in tails["arm"]] == [39.0, 40.0]
    assert [row.total_s for row in tails["other"]] == [5.0]
    tail_row = next(line for line in script.table(rows) if line.startswith(f"| arm | {script.TAIL} |"))
    assert tail_row.split("|")[3:5] == [" 2 ", " 39500.0 "]  # planned, median plan [ms]


def test_a_computation_is_charged_all_it_calls_and_its_own_nested_calls_once(script: ModuleType) -> None:
    now = [0.0]
    clock = script.ComputationClock(clock=lambda: now[0])

    def leaf() -> None:
        now[0] += 2.0

    timed_leaf = clock.wrapped("RNEA", leaf)

    def recursive(depth: int) -> int:
        now[0] += 1.0
        timed_leaf()
        return depth if depth == 0 else timed_recursive(depth - 1)

    timed_recursive = clock.wrapped("closest pairs", recursive)
    assert timed_recursive(2) == 0 and timed_recursive.__name__ == "recursive"
    assert clock.spent_s == {"closest pairs": 9.0, "RNEA": 6.0}  # inclusive; three levels counted once
    assert clock.lap() == {**dict.fromkeys(script.COMPUTATIONS, 0.0), "closest pairs": 9.0, "RNEA": 6.0}
    assert clock.lap() == dict.fromkeys(script.COMPUTATIONS, 0.0)


def test_every_computation_names_a_function_of_the_code(script: ModuleType) -> None:
    import importlib

    for module_name, attribute in script.COMPUTATIONS.values():
        owner = importlib.import_module(module_name)
        for part in attribute.split("."):
            owner = getattr(owner, part)
        assert callable(owner), attribute


def test_the_computations_table_gives_each_s_summed_time_and_share(script: ModuleType) -> None:
    stages = dict.fromkeys(script.STAGES, 0.0)
    rows = [
        script.Profiled("arm", "box", 1.0, stages, 1.1, 2.0, {"closest pairs": 0.25, "RNEA": 0.1}),
        script.Profiled("arm", "cage", 3.0, stages, 1.3, 3.0, {"closest pairs": 0.75}),
    ]
    lines = script.computations_table(rows)
    every = next(line for line in lines if line.startswith("| arm | all |"))
    cells = dict(
        zip(
            ["robot", "class", "planned", "summed", *script.COMPUTATIONS],
            every.strip("|").split("|"),
            strict=True,
        )
    )
    assert cells["planned"].strip() == "2" and cells["summed"].strip() == "4.000"
    assert cells["closest pairs"].strip() == "1.000 (25%)" and cells["RNEA"].strip() == "0.100 (2%)"
    assert cells["extrema"].strip() == "0.000 (0%)"


@pytest.mark.slow
def test_the_script_profiles_a_scene_file_and_its_stages_add_up(script: ModuleType, tmp_path: Path) -> None:
    run = subprocess.run(
        [sys.executable, str(SCRIPT), "--scenes", str(SHELF), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    line = next(line for line in run.stdout.splitlines() if line.startswith("scenes shelf:"))
    total = float(re.search(r": (\d+) ms", line).group(1))  # type: ignore[union-attr]
    stages = line.split("(", 1)[1].split(")", 1)[0]
    spent = {name: float(ms) for name, ms in re.findall(r"(\w+) (\d+)", stages)}
    assert set(spent) == set(script.STAGES)
    assert spent["build"] > 0 and spent["verify"] > 0 and spent["timing"] > 0  # the wrapped functions ran
    assert sum(spent.values()) <= total + len(spent)  # each rounded to a millisecond
    assert "| scenes | shelf | 1 |" in (tmp_path / "stages.md").read_text()
    bought = (tmp_path / "computations.md").read_text()
    row = next(row for row in bought.splitlines() if row.startswith("| scenes | shelf | 1 |"))
    seconds = dict(zip(script.COMPUTATIONS, re.findall(r"([\d.]+) \(\d+%\)", row), strict=True))
    assert float(seconds["obstacle tests"]) > 0 and float(seconds["extrema"]) > 0  # the wrapped ones ran
    assert all(float(value) <= total / 1000 for value in seconds.values())  # each within the plan
    over_bound = float(re.search(r"\), ([\d.]+) of Ruckig's bound", line).group(1))  # type: ignore[union-attr]
    assert over_bound >= 1.0  # no trajectory beats the jerk-limited straight line


def test_a_planner_setting_is_read_as_a_scene_file_reads_it(script: ModuleType) -> None:
    assert script.planner_setting("iterations=0") == ("iterations", 0)
    assert script.planner_setting("refine=none") == ("refine", "none")
    assert script.planner_setting("near_bound=1.5") == ("near_bound", 1.5)
    for bad in ("iterations", "=3", "seed="):
        with pytest.raises(argparse.ArgumentTypeError, match="is not KEY=VALUE"):
            script.planner_setting(bad)
    with pytest.raises(argparse.ArgumentTypeError, match="the value is not YAML"):
        script.planner_setting("seed=[1,")


@pytest.mark.slow
@pytest.mark.parametrize(
    ("scene", "message"),
    [
        ("no/such/scene.yaml", "--scenes no/such/scene.yaml: no such file or folder"),
        (str(TASK), "holds a task of 8 segments, not one motion to a goal"),
        (f"{SHELF} --planner iterations=-1", "iterations"),
        (f"{SHELF} --planner no_such_setting=1", "no_such_setting"),
        (f"{SHELF} --planner time_limit_s=3", "give the time limit as --time-limit S"),
    ],
)
def test_a_scene_it_cannot_profile_is_refused_in_one_line(scene: str, message: str) -> None:
    run = subprocess.run(
        [sys.executable, str(SCRIPT), "--scenes", *scene.split()],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 2 and message in run.stderr
    assert "Traceback" not in run.stderr
