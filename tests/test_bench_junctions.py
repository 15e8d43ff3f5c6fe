"""``scripts/bench_junctions.py``: a task's junctions against a stop at every one, as a user runs it."""

from __future__ import annotations

import pytest

from .conftest import run_script, script_table


@pytest.mark.slow
def test_every_task_takes_at_most_its_stops_and_the_row_counts_its_junctions() -> None:
    rows = script_table("bench_junctions", "--tasks", "2", "--seed", "3", "--robots", "cpr")
    assert rows[0][:3] == ["robot", "task", "planned"]
    assert [row[:2] for row in rows[1:]] == [["cpr", "three moves"], ["cpr", "move, line up, move"]]
    for row in rows[1:]:
        assert row[2] == "2"
        task_s, stopping_s, median, largest = (float(cell) for cell in row[3:7])
        assert 0.0 < task_s <= stopping_s + 1e-3 and median <= largest <= 1.0 + 1e-9
        passed, junctions = (int(cell) for cell in row[7].split(" of "))
        assert junctions == 4 and 0 <= passed <= junctions


def test_an_unknown_robot_is_one_line_naming_the_choices() -> None:
    done = run_script("bench_junctions", "--robots", "r2d2", timeout_s=60)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert "argument --robots: invalid choice: 'r2d2'" in done.stderr and "panda" in done.stderr
